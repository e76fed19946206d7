#pragma once
// The laboratory's record of every grain (docs/laboratory.md §3.3), kept beside the engine's particle
// arrays, not in them: reference position and orientation (the state at the start of shearing),
// the path integral of |omega| dt since then, and the sphericity a grain was given ([R]). Indexed like
// the particles; Laboratory keeps the two in step.
#include <iosfwd>
#include <vector>

#include "core/simulation.hpp"

namespace grainlab::lab {

struct GrainRecords {
  std::vector<Vec3> referencePosition;     // unwrapped position at the reference state [m]
  std::vector<Quat> referenceOrientation;
  std::vector<double> rotationPath;        // integral of |omega| dt since the reference [rad]
  std::vector<double> sphericity;          // true sphericity ([R]); 1 where none was given
  Mat3 referenceCell = Mat3::Identity();   // periodic cell matrix at the reference state

  // Starts the record anew from the current state (sphericity is kept, or set to 1).
  void reset(const Simulation& sim);
  // Adds |omega| dt of the step just taken to particles [begin, end) (an inner stage of the step,
  // right after the engine's integration, shared out by particle).
  void accumulateRotation(const Particles& particles, double dt, std::size_t begin, std::size_t end);
  // Angle [rad] of the composed rotation of particle i since its reference orientation.
  double rotationAngle(const Particles& particles, std::size_t i) const;
  // Displacement of particle i since the reference, continued through the faces of a periodic cell.
  Vec3 displacement(const Simulation& sim, std::size_t i) const;

  void saveState(std::ostream& out) const;
  void loadState(std::istream& in);
};

}  // namespace grainlab::lab

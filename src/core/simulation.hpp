#pragma once
// The DEM engine for spheres in a box of rigid walls. One call of step() runs the pipeline
//
//   broad phase (Verlet list, rebuilt when due) -> narrow phase + contact law (per pair, parallel)
//   -> wall forces & servos -> per particle: force gather (fixed order) + integrator (leapfrog +
//   damping), fused in one parallel pass
//
// Laboratory protocols drive it from outside (recorders and stop checks between steps).
#include <string>
#include <vector>

#include "contact/models.hpp"
#include "core/neighbor_list.hpp"
#include "core/particles.hpp"
#include "core/servo_settings.hpp"
#include "core/walls.hpp"

namespace grainlab {

// Cumulative energy terms tracked by the engine [J] (PHYSICS.md §7.6, partial).
struct EnergyLedger {
  double slip = 0.0;
  double rolling = 0.0;
  double damping = 0.0;
  double boundaryWork = 0.0;  // work done on the particles by the walls
};

class Simulation {
 public:
  Particles particles;
  WallBox box;
  NeighborList neighbors;
  contact::SphereContactModel model;
  ServoSettings servo;
  EnergyLedger energy;

  Vec3 gravity = Vec3::Zero();  // [m/s^2]; off in the triaxial tests of [W]
  double dt = 0.0;            // [s]
  double localDamping = 0.3;  // Cundall alpha [-]
  long stepCount = 0;
  double time = 0.0;          // [s]

  // Per-contact results of the latest step (parallel to neighbors' arrays).
  std::vector<Vec3> pairForce;    // force of A on B [N]
  std::vector<Vec3> pairTorqueA;  // total torque on A from this contact [N m]
  std::vector<Vec3> pairTorqueB;
  std::vector<Vec3> wallForce;    // force of the wall on the particle [N]
  std::vector<Vec3> wallTorque;

  // Sets the neighbour skin from the particle sizes; call after adding particles.
  void initialise(double skinFraction = 0.2);
  // Critical time step (PHYSICS.md §4): min over particles of sqrt(m/Kn) and sqrt(I/K_theta) for
  // the stiffest contact the particle can have (against a wall).
  double criticalTimeStep() const;
  void step();

  // Number of touching particle-particle contacts at the latest step.
  std::size_t touchingPairs() const;

  // Exact binary state for checkpoints: a loaded simulation continues bit for bit.
  void saveState(std::ostream& out) const;
  void loadState(std::istream& in);
  // Consistency of a loaded state before it is stepped (state_validate.cpp): sizes agree, indices
  // in range, numbers finite. Throws InputError saying what is wrong.
  void validateState() const;

 private:
  void computeContacts();
  void sumWallForces();
  void gatherParticle(std::size_t i);
  void updateWalls();
  void integrate();
  bool rebuildDue_ = true;
  bool slotsStale_ = true;  // pair/wall force slots not yet written since the last rebuild or load
};

}  // namespace grainlab

#pragma once
// Particle storage as structure-of-arrays: the hot loops touch only the arrays they need.
#include <iosfwd>
#include <vector>

#include "core/types.hpp"

namespace grainlab {

struct Particles {
  // Kinematic state.
  std::vector<Vec3> position;
  std::vector<Vec3> velocity;         // translational velocity [m/s] (mid-step in leapfrog)
  std::vector<Quat> orientation;      // body orientation (unit quaternion)
  std::vector<Vec3> angularVelocity;  // [rad/s] (mid-step)
  // Accumulators, cleared and refilled every step.
  std::vector<Vec3> force;   // [N]
  std::vector<Vec3> torque;  // [N m]
  // Shape and mass.
  std::vector<double> radius;   // [m]
  std::vector<double> mass;     // [kg]
  std::vector<double> inertia;  // [kg m^2], 2/5 m R^2 for spheres
  // 1/m and 1/I, derived from mass and inertia (not saved in checkpoints; rebuilt on load): the
  // integrator multiplies instead of dividing twice per particle and step.
  std::vector<double> invMass;
  std::vector<double> invInertia;
  // Per-grain contact properties ([R]): rolling friction mu_r [-] and the true sphericity it came
  // from (1 where not given).
  std::vector<double> rollingFriction;
  std::vector<double> sphericity;
  // Kinematic record (PHYSICS.md §7.4): reference position and orientation, and the path integral
  // of |w| dt since then.
  std::vector<Vec3> referencePosition;
  std::vector<Quat> referenceOrientation;
  std::vector<double> rotationPath;  // [rad]

  std::size_t size() const { return position.size(); }
  void addSphere(const Vec3& x, double r, double density);
  // Overrides a particle's mass and moment of inertia (keeps 1/m and 1/I in step).
  void setMass(std::size_t i, double m, double inertiaValue) {
    mass[i] = m;
    inertia[i] = inertiaValue;
    invMass[i] = 1.0 / m;
    invInertia[i] = 1.0 / inertiaValue;
  }
  // Starts the kinematic record anew (e.g. at the start of shearing).
  void resetKinematicReference();
  // Angle [rad] of the composed rotation of particle i since its reference orientation.
  double rotationAngle(std::size_t i) const;
  double solidVolume() const;
  // Exact binary state for checkpoints (state_io.hpp).
  void saveState(std::ostream& out) const;
  void loadState(std::istream& in);
};

}  // namespace grainlab

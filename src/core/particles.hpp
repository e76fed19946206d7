#pragma once
// Particle storage as structure-of-arrays: the hot loops touch only the arrays they need. Only what
// the step needs lives here; laboratory records (reference positions, rotation paths, sphericity)
// are kept by the laboratory (lab/grain_records.hpp), outside the hot arrays.
#include <array>
#include <cstdint>
#include <iosfwd>
#include <vector>

#include "core/types.hpp"

namespace grainlab {

// Particle shapes the engine knows. A sphere has semi-axes (r, r, r).
enum class Shape : std::uint8_t { Sphere = 0, Ellipsoid = 1 };

struct Particles {
  // Persistent identity: an id stays with its particle when storage is reordered or a packing file
  // is read (ids come from the file); the storage index is only a position in these arrays.
  std::vector<std::uint64_t> id;
  // Kinematic state.
  std::vector<Vec3> position;
  std::vector<Vec3> velocity;         // translational velocity [m/s] (mid-step in leapfrog); in a
                                      // periodic cell relative to the homogeneous flow L x
  std::vector<Quat> orientation;      // body orientation (unit quaternion)
  std::vector<Vec3> angularVelocity;  // [rad/s] (mid-step)
  // Accumulators, cleared and refilled every step.
  std::vector<Vec3> force;   // [N]
  std::vector<Vec3> torque;  // [N m]
  // Shape and mass.
  std::vector<Shape> shape;
  std::vector<double> radius;   // [m] sphere radius; for other shapes the bounding radius
  std::vector<Vec3> semiAxes;   // [m] along the body axes; (r, r, r) for spheres
  std::vector<double> mass;     // [kg]
  std::vector<double> inertia;  // [kg m^2], 2/5 m R^2 for spheres (ellipsoids: the mean principal moment)
  // Non-spherical bodies: principal moments along the body axes [kg m^2] ((I, I, I) for spheres),
  // the world angular momentum at mid-step [kg m^2/s] that their rotation integrator keeps exact
  // (zero for spheres, which need none), and the equivalent radius (abc)^(1/3) the contact
  // stiffness is computed from ([O]; the radius itself for spheres).
  std::vector<Vec3> principalInertia;
  std::vector<Vec3> angularMomentum;
  std::vector<double> equivalentRadius;
  // 1/m and 1/I, derived from mass and inertia (not saved in checkpoints; rebuilt on load): the
  // integrator multiplies instead of dividing twice per particle and step.
  std::vector<double> invMass;
  std::vector<double> invInertia;
  // Per-grain contact property ([R]): rolling friction mu_r [-].
  std::vector<double> rollingFriction;
  // Periods crossed in a periodic cell (LAMMPS's image flags): the unwrapped position x + H image
  // follows a particle continuously through the faces. Zero in a wall box.
  std::vector<std::array<std::int32_t, 3>> image;

  std::size_t size() const { return position.size(); }
  // Appends a sphere; its id is `newId`, or its index when newId is kNoId.
  static constexpr std::uint64_t kNoId = ~std::uint64_t{0};
  void addSphere(const Vec3& x, double r, double density, std::uint64_t newId = kNoId);
  // Appends an ellipsoid of semi-axes a >= b >= c along its body x, y, z axes, orientation q (body
  // to world), at rest.
  void addEllipsoid(const Vec3& x, const Vec3& semiAxes, const Quat& q, double density, std::uint64_t newId = kNoId);
  // Gives particle i new semi-axes (a sphere when all three are equal) keeping its density:
  // mass, inertia and the angular momentum of its current spin follow.
  void setShape(std::size_t i, const Vec3& semiAxes, double density);
  bool anyEllipsoid() const;
  // Sets particle i's angular velocity [rad/s]; for an ellipsoid also its angular momentum, which
  // is the state its integrator advances (writing angularVelocity alone would be overwritten).
  void setAngularVelocity(std::size_t i, const Vec3& w);
  // Overrides a particle's mass and moment of inertia (keeps 1/m and 1/I in step).
  void setMass(std::size_t i, double m, double inertiaValue) {
    mass[i] = m;
    inertia[i] = inertiaValue;
    invMass[i] = 1.0 / m;
    invInertia[i] = 1.0 / inertiaValue;
  }
  // Changes a sphere's radius keeping its density (mass and inertia follow).
  void setSphereRadius(std::size_t i, double r, double density);
  double solidVolume() const;
  // Position continued through the faces of a periodic cell with matrix h (x + h image).
  Vec3 unwrapped(std::size_t i, const Mat3& h) const {
    return position[i] + h * Vec3(image[i][0], image[i][1], image[i][2]);
  }
  // Exact binary state for checkpoints (state_io.hpp).
  void saveState(std::ostream& out) const;
  // Reads the stored arrays only; nothing is derived from them until deriveAfterLoad(), which the
  // caller runs after the loaded state has been validated (a forged file must not index anything).
  void loadState(std::istream& in);
  void deriveAfterLoad();
};

}  // namespace grainlab

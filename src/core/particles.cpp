#include "core/particles.hpp"

#include <algorithm>
#include <cmath>

#include "core/state_io.hpp"

namespace grainlab {

void Particles::addSphere(const Vec3& x, double r, double density) {
  const double m = 4.0 / 3.0 * kPi * r * r * r * density;
  position.push_back(x);
  velocity.push_back(Vec3::Zero());
  orientation.push_back(Quat::Identity());
  angularVelocity.push_back(Vec3::Zero());
  force.push_back(Vec3::Zero());
  torque.push_back(Vec3::Zero());
  radius.push_back(r);
  mass.push_back(m);
  inertia.push_back(0.4 * m * r * r);
  invMass.push_back(1.0 / mass.back());
  invInertia.push_back(1.0 / inertia.back());
  rollingFriction.push_back(0.0);
  sphericity.push_back(1.0);
  referencePosition.push_back(x);
  referenceOrientation.push_back(Quat::Identity());
  rotationPath.push_back(0.0);
}

void Particles::resetKinematicReference() {
  referencePosition = position;
  referenceOrientation = orientation;
  for (auto& p : rotationPath) p = 0.0;
}

double Particles::rotationAngle(std::size_t i) const {
  const Quat rel = orientation[i] * referenceOrientation[i].conjugate();
  // |w| of a unit quaternion is cos(theta/2) up to sign; take the shorter rotation.
  const double w = std::min(1.0, std::abs(rel.w()));
  return 2.0 * std::acos(w);
}

void Particles::saveState(std::ostream& out) const {
  using namespace stateio;
  putVector(out, position);
  putVector(out, velocity);
  putVector(out, orientation);
  putVector(out, angularVelocity);
  putVector(out, force);
  putVector(out, torque);
  putVector(out, radius);
  putVector(out, mass);
  putVector(out, inertia);
  putVector(out, rollingFriction);
  putVector(out, sphericity);
  putVector(out, referencePosition);
  putVector(out, referenceOrientation);
  putVector(out, rotationPath);
}

void Particles::loadState(std::istream& in) {
  using namespace stateio;
  getVector(in, position);
  getVector(in, velocity);
  getVector(in, orientation);
  getVector(in, angularVelocity);
  getVector(in, force);
  getVector(in, torque);
  getVector(in, radius);
  getVector(in, mass);
  getVector(in, inertia);
  invMass.resize(mass.size());
  invInertia.resize(inertia.size());
  for (std::size_t i = 0; i < mass.size(); ++i) {
    invMass[i] = 1.0 / mass[i];
    invInertia[i] = 1.0 / inertia[i];
  }
  getVector(in, rollingFriction);
  getVector(in, sphericity);
  getVector(in, referencePosition);
  getVector(in, referenceOrientation);
  getVector(in, rotationPath);
}

double Particles::solidVolume() const {
  double v = 0.0;
  for (double r : radius) v += 4.0 / 3.0 * kPi * r * r * r;
  return v;
}

}  // namespace grainlab

#include "core/particles.hpp"

#include <algorithm>
#include <cmath>

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

double Particles::solidVolume() const {
  double v = 0.0;
  for (double r : radius) v += 4.0 / 3.0 * kPi * r * r * r;
  return v;
}

}  // namespace grainlab

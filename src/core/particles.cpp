#include "core/particles.hpp"

#include <algorithm>
#include <cmath>

#include "core/state_io.hpp"
#include "geometry/ellipsoid_shape.hpp"

namespace grainlab {

void Particles::addSphere(const Vec3& x, double r, double density, std::uint64_t newId) {
  const double m = 4.0 / 3.0 * kPi * r * r * r * density;
  id.push_back(newId == kNoId ? static_cast<std::uint64_t>(position.size()) : newId);
  position.push_back(x);
  velocity.push_back(Vec3::Zero());
  orientation.push_back(Quat::Identity());
  angularVelocity.push_back(Vec3::Zero());
  force.push_back(Vec3::Zero());
  torque.push_back(Vec3::Zero());
  shape.push_back(Shape::Sphere);
  radius.push_back(r);
  semiAxes.push_back(Vec3::Constant(r));
  mass.push_back(m);
  inertia.push_back(0.4 * m * r * r);
  invMass.push_back(1.0 / mass.back());
  invInertia.push_back(1.0 / inertia.back());
  rollingFriction.push_back(0.0);
  image.push_back({0, 0, 0});
  principalInertia.push_back(Vec3::Constant(inertia.back()));
  angularMomentum.push_back(Vec3::Zero());
  equivalentRadius.push_back(r);
}

void Particles::addEllipsoid(const Vec3& x, const Vec3& semiAxes, const Quat& q, double density, std::uint64_t newId) {
  addSphere(x, semiAxes.maxCoeff(), density, newId);
  orientation.back() = q.normalized();
  setShape(size() - 1, semiAxes, density);
}

void Particles::setShape(std::size_t i, const Vec3& s, double density) {
  if (s[0] == s[1] && s[1] == s[2]) {
    const Vec3 w = angularVelocity[i];
    shape[i] = Shape::Sphere;
    setSphereRadius(i, s[0], density);
    principalInertia[i] = Vec3::Constant(inertia[i]);
    angularMomentum[i].setZero();
    angularVelocity[i] = w;
    return;
  }
  shape[i] = Shape::Ellipsoid;
  semiAxes[i] = s;
  radius[i] = geometry::boundingRadius(s);
  equivalentRadius[i] = geometry::equivalentRadius(s);
  const double m = geometry::ellipsoidMass(s, density);
  principalInertia[i] = geometry::ellipsoidPrincipalInertia(s, m);
  setMass(i, m, principalInertia[i].mean());
  setAngularVelocity(i, angularVelocity[i]);  // L = I_world w of the current spin
}

void Particles::setAngularVelocity(std::size_t i, const Vec3& w) {
  angularVelocity[i] = w;
  if (shape[i] == Shape::Ellipsoid) {
    const Quat& q = orientation[i];
    angularMomentum[i] = q * principalInertia[i].cwiseProduct(q.conjugate() * w);
  }
}

bool Particles::anyEllipsoid() const {
  for (Shape s : shape)
    if (s == Shape::Ellipsoid) return true;
  return false;
}

void Particles::setSphereRadius(std::size_t i, double r, double density) {
  const double m = 4.0 / 3.0 * kPi * r * r * r * density;
  radius[i] = r;
  semiAxes[i] = Vec3::Constant(r);
  equivalentRadius[i] = r;
  setMass(i, m, 0.4 * m * r * r);
  principalInertia[i] = Vec3::Constant(inertia[i]);
}

double Particles::solidVolume() const {
  double v = 0.0;
  // ((4/3 pi a) b) c: for a sphere the same operations, in the same order, as 4/3 pi r r r.
  for (const Vec3& s : semiAxes) v += 4.0 / 3.0 * kPi * s[0] * s[1] * s[2];
  return v;
}

void Particles::saveState(std::ostream& out) const {
  using namespace stateio;
  putVector(out, id);
  putVector(out, position);
  putVector(out, velocity);
  putVector(out, orientation);
  putVector(out, angularVelocity);
  putVector(out, force);
  putVector(out, torque);
  putVector(out, shape);
  putVector(out, radius);
  putVector(out, semiAxes);
  putVector(out, mass);
  putVector(out, inertia);
  putVector(out, rollingFriction);
  putVector(out, image);
  putVector(out, principalInertia);
  putVector(out, angularMomentum);
}

void Particles::loadState(std::istream& in) {
  using namespace stateio;
  getVector(in, id);
  getVector(in, position);
  getVector(in, velocity);
  getVector(in, orientation);
  getVector(in, angularVelocity);
  getVector(in, force);
  getVector(in, torque);
  getVector(in, shape);
  getVector(in, radius);
  getVector(in, semiAxes);
  getVector(in, mass);
  getVector(in, inertia);
  getVector(in, rollingFriction);
  getVector(in, image);
  getVector(in, principalInertia);
  getVector(in, angularMomentum);
}

void Particles::deriveAfterLoad() {
  // Called only after Simulation::validateState() has checked every array's size and value.
  equivalentRadius.resize(semiAxes.size());
  for (std::size_t i = 0; i < semiAxes.size(); ++i)
    equivalentRadius[i] = shape[i] == Shape::Sphere ? radius[i] : geometry::equivalentRadius(semiAxes[i]);
  invMass.resize(mass.size());
  invInertia.resize(inertia.size());
  for (std::size_t i = 0; i < mass.size(); ++i) {
    invMass[i] = 1.0 / mass[i];
    invInertia[i] = 1.0 / inertia[i];
  }
}

}  // namespace grainlab

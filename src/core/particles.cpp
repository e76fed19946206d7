#include "core/particles.hpp"

#include <algorithm>
#include <cmath>

#include "core/state_io.hpp"

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
}

void Particles::setSphereRadius(std::size_t i, double r, double density) {
  const double m = 4.0 / 3.0 * kPi * r * r * r * density;
  radius[i] = r;
  semiAxes[i] = Vec3::Constant(r);
  setMass(i, m, 0.4 * m * r * r);
}

double Particles::solidVolume() const {
  double v = 0.0;
  // ((4/3 pi a) b) c: for a sphere the same operations, in the same order, as 4/3 pi r r r.
  for (const Vec3& s : semiAxes) v += 4.0 / 3.0 * kPi * s[0] * s[1] * s[2];
  return v;
}

namespace {
template <class T>
void applyOrder(std::vector<T>& v, const std::vector<std::uint32_t>& order) {
  std::vector<T> out;
  out.reserve(order.size());
  for (std::uint32_t k : order) out.push_back(v[k]);
  v.swap(out);
}
}  // namespace

void Particles::permute(const std::vector<std::uint32_t>& order) {
  applyOrder(id, order);
  applyOrder(position, order);
  applyOrder(velocity, order);
  applyOrder(orientation, order);
  applyOrder(angularVelocity, order);
  applyOrder(force, order);
  applyOrder(torque, order);
  applyOrder(shape, order);
  applyOrder(radius, order);
  applyOrder(semiAxes, order);
  applyOrder(mass, order);
  applyOrder(inertia, order);
  applyOrder(invMass, order);
  applyOrder(invInertia, order);
  applyOrder(rollingFriction, order);
  applyOrder(image, order);
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
  invMass.resize(mass.size());
  invInertia.resize(inertia.size());
  for (std::size_t i = 0; i < mass.size(); ++i) {
    invMass[i] = 1.0 / mass[i];
    invInertia[i] = 1.0 / inertia[i];
  }
}

}  // namespace grainlab

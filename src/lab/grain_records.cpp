#include "lab/grain_records.hpp"

#include <algorithm>
#include <cmath>

#include "core/state_io.hpp"

namespace grainlab::lab {

void GrainRecords::reset(const Simulation& sim) {
  const Particles& P = sim.particles;
  const std::size_t n = P.size();
  const bool periodic = sim.boundary == Boundary::Periodic;
  referencePosition.resize(n);
  for (std::size_t i = 0; i < n; ++i) referencePosition[i] = periodic ? P.unwrapped(i, sim.cell.h) : P.position[i];
  referenceOrientation = P.orientation;
  rotationPath.assign(n, 0.0);
  if (sphericity.size() != n) sphericity.assign(n, 1.0);
  referenceCell = sim.cell.h;
}

void GrainRecords::accumulateRotation(const Particles& particles, double dt, std::size_t begin, std::size_t end) {
  const auto& w = particles.angularVelocity;
  end = std::min(end, rotationPath.size());
  for (std::size_t i = begin; i < end; ++i) {
    const double wNorm = w[i].norm();
    if (wNorm > 0.0) rotationPath[i] += wNorm * dt;
  }
}

double GrainRecords::rotationAngle(const Particles& particles, std::size_t i) const {
  const Quat rel = particles.orientation[i] * referenceOrientation[i].conjugate();
  // |w| of a unit quaternion is cos(theta/2) up to sign; take the shorter rotation.
  const double w = std::min(1.0, std::abs(rel.w()));
  return 2.0 * std::acos(w);
}

Vec3 GrainRecords::displacement(const Simulation& sim, std::size_t i) const {
  const Vec3 now = sim.boundary == Boundary::Periodic ? sim.particles.unwrapped(i, sim.cell.h) : sim.particles.position[i];
  return now - referencePosition[i];
}

void GrainRecords::saveState(std::ostream& out) const {
  using namespace stateio;
  putVector(out, referencePosition);
  putVector(out, referenceOrientation);
  putVector(out, rotationPath);
  putVector(out, sphericity);
  put(out, referenceCell);
}

void GrainRecords::loadState(std::istream& in) {
  using namespace stateio;
  getVector(in, referencePosition);
  getVector(in, referenceOrientation);
  getVector(in, rotationPath);
  getVector(in, sphericity);
  get(in, referenceCell);
}

}  // namespace grainlab::lab

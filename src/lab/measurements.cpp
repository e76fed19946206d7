#include "lab/measurements.hpp"

#include <cmath>

namespace grainlab::lab {

double unbalancedForceRatio(const Simulation& sim) {
  const auto& P = sim.particles;
  double net = 0.0;
  for (std::size_t i = 0; i < P.size(); ++i) net += (P.force[i] + P.mass[i] * sim.gravity).norm();
  double contactSum = 0.0;
  std::size_t contacts = 0;
  const auto& nl = sim.neighbors;
  for (std::size_t p = 0; p < nl.pairA.size(); ++p)
    if (nl.pairHistory[p].touching) {
      contactSum += sim.pairForce[p].norm();
      ++contacts;
    }
  for (std::size_t c = 0; c < nl.wallParticle.size(); ++c)
    if (nl.wallHistory[c].touching) {
      contactSum += sim.wallForce[c].norm();
      ++contacts;
    }
  if (contacts == 0 || contactSum <= 0.0) return 1.0;
  return (net / static_cast<double>(P.size())) / (contactSum / static_cast<double>(contacts));
}

Mat3 contactStress(const Simulation& sim) {
  const auto& nl = sim.neighbors;
  const auto& x = sim.particles.position;
  const auto& r = sim.particles.radius;
  Mat3 s = Mat3::Zero();
  for (std::size_t p = 0; p < nl.pairA.size(); ++p) {
    if (!nl.pairHistory[p].touching) continue;
    const Vec3 branch = x[nl.pairB[p]] - x[nl.pairA[p]];
    s += sim.pairForce[p] * branch.transpose();
  }
  for (std::size_t c = 0; c < nl.wallParticle.size(); ++c) {
    if (!nl.wallHistory[c].touching) continue;
    const std::uint32_t i = nl.wallParticle[c];
    const Wall& wall = sim.box.walls[nl.wallIndex[c]];
    const Vec3 n = wall.inwardNormal();
    const double gap = wall.distance(x[i]);
    const double overlap = r[i] - gap;
    const Vec3 toContact = -(r[i] - 0.5 * overlap) * n;  // x^c - x^p
    s -= sim.wallForce[c] * toContact.transpose();
  }
  return s / sim.box.volume();
}

Vec3 wallStress(const Simulation& sim) {
  return {sim.box.stress(0), sim.box.stress(1), sim.box.stress(2)};
}

double voidRatio(const Simulation& sim) {
  return sim.box.volume() / sim.particles.solidVolume() - 1.0;
}

std::vector<int> contactsPerParticle(const Simulation& sim) {
  std::vector<int> contacts(sim.particles.size(), 0);
  const auto& nl = sim.neighbors;
  for (std::size_t p = 0; p < nl.pairA.size(); ++p)
    if (nl.pairHistory[p].touching) {
      ++contacts[nl.pairA[p]];
      ++contacts[nl.pairB[p]];
    }
  for (std::size_t c = 0; c < nl.wallParticle.size(); ++c)
    if (nl.wallHistory[c].touching) ++contacts[nl.wallParticle[c]];
  return contacts;
}

double coordinationNumber(const Simulation& sim) {
  return 2.0 * static_cast<double>(sim.touchingPairs()) / static_cast<double>(sim.particles.size());
}

double kineticEnergy(const Simulation& sim) {
  const auto& P = sim.particles;
  double e = 0.0;
  for (std::size_t i = 0; i < P.size(); ++i)
    e += 0.5 * P.mass[i] * P.velocity[i].squaredNorm() +
         0.5 * P.inertia[i] * P.angularVelocity[i].squaredNorm();
  return e;
}

double elasticEnergy(const Simulation& sim) {
  const auto& nl = sim.neighbors;
  const auto& r = sim.particles.radius;
  const auto& x = sim.particles.position;
  double e = 0.0;
  auto springs = [&](const contact::PairParams& pp, double overlap, const contact::ContactHistory& h) {
    double u = 0.5 * pp.kn * overlap * overlap;
    if (pp.ks > 0.0) u += 0.5 * h.shearForce.squaredNorm() / pp.ks;
    if (pp.kr > 0.0) u += 0.5 * h.moment.squaredNorm() / pp.kr;
    return u;
  };
  for (std::size_t p = 0; p < nl.pairA.size(); ++p) {
    if (!nl.pairHistory[p].touching) continue;
    const std::uint32_t a = nl.pairA[p], b = nl.pairB[p];
    const double overlap = r[a] + r[b] - (x[b] - x[a]).norm();
    const auto& mu = sim.particles.rollingFriction;
    e += springs(sim.model.pairParams(r[a], r[b], mu[a], mu[b]), overlap, nl.pairHistory[p]);
  }
  for (std::size_t c = 0; c < nl.wallParticle.size(); ++c) {
    if (!nl.wallHistory[c].touching) continue;
    const std::uint32_t i = nl.wallParticle[c];
    const Wall& wall = sim.box.walls[nl.wallIndex[c]];
    const double gap = wall.distance(x[i]);
    e += springs(sim.model.wallParams(r[i], wall.tanFriction, sim.particles.rollingFriction[i]), r[i] - gap,
                 nl.wallHistory[c]);
  }
  return e;
}

}  // namespace grainlab::lab

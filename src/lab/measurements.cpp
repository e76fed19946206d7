#include "lab/measurements.hpp"

#include <cmath>
#include <vector>

#include "core/contact_view.hpp"

namespace grainlab::lab {

double unbalancedForceRatio(const Simulation& sim) {
  const auto& P = sim.particles;
  double net = 0.0;
  for (std::size_t i = 0; i < P.size(); ++i) net += (P.force[i] + P.mass[i] * sim.gravity).norm();
  double contactSum = 0.0;
  std::size_t contacts = 0;
  forEachTouchingContact(sim, [&](const ContactView& c) {
    contactSum += c.force.norm();
    ++contacts;
  });
  if (contacts == 0 || contactSum <= 0.0) return 1.0;
  return (net / static_cast<double>(P.size())) / (contactSum / static_cast<double>(contacts));
}

Mat3 contactStress(const Simulation& sim) {
  // In a cell the contact stage sums the same terms with the forces and branches of one
  // configuration, every step (the servo needs it).
  if (sim.boundary == Boundary::Periodic) return sim.cell.stress;
  Mat3 s = Mat3::Zero();
  forEachTouchingContact(sim, [&](const ContactView& c) {
    if (c.wall) s -= c.force * c.branch.transpose();  // the wall's force on the particle, arm x^c - x^p
    else s += c.force * c.branch.transpose();
  });
  // The membrane's forces act at the grains' outermost points, r along the outward radial.
  const Membrane& m = sim.membrane;
  if (sim.boundary == Boundary::Membrane)
    for (std::size_t k = 0; k < m.grain.size(); ++k) {
      const double f = m.force[k].norm();
      if (f > 0.0) s -= m.force[k] * (-sim.particles.radius[m.grain[k]] / f * m.force[k]).transpose();
    }
  return s / sim.volume();
}

Mat3 unbalancedStress(const Simulation& sim) {
  if (sim.boundary == Boundary::Periodic) return Mat3::Zero();
  const auto& x = sim.particles.position;
  std::vector<Vec3> net(x.size(), Vec3::Zero());
  forEachTouchingContact(sim, [&](const ContactView& c) {
    if (c.wall) {
      net[c.a] += c.force;  // the wall's force on a
    } else {
      net[c.b] += c.force;  // a's force on b
      net[c.a] -= c.force;
    }
  });
  if (sim.boundary == Boundary::Membrane)
    for (std::size_t k = 0; k < sim.membrane.grain.size(); ++k) net[sim.membrane.grain[k]] += sim.membrane.force[k];
  const Vec3 centre = 0.5 * (sim.box.lowerCorner() + sim.box.upperCorner());
  Mat3 u = Mat3::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) u -= net[i] * (x[i] - centre).transpose();
  return u / sim.volume();
}

Vec3 boundaryStress(const Simulation& sim) {
  if (sim.boundary == Boundary::Periodic) return sim.cell.stress.diagonal();
  if (sim.boundary == Boundary::Membrane) {
    const double r = sim.membrane.radialStress();
    return {r, r, 0.5 * (sim.wallStress(WallBox::index(2, 0)) + sim.wallStress(WallBox::index(2, 1)))};
  }
  return {sim.box.stress(0), sim.box.stress(1), sim.box.stress(2)};
}

std::array<double, 6> singleWallStresses(const Simulation& sim) {
  std::array<double, 6> s{};
  if (sim.boundary == Boundary::Walls)
    for (int k = 0; k < 6; ++k) s[k] = sim.box.wallStress(k);
  if (sim.boundary == Boundary::Membrane)
    for (int k = 0; k < 6; ++k) s[k] = k < 4 ? sim.membrane.radialStress() : sim.wallStress(k);
  return s;
}

Vec3 sampleLengths(const Simulation& sim) {
  if (sim.boundary == Boundary::Periodic) return sim.cell.h.diagonal();
  if (sim.boundary == Boundary::Membrane) {
    const double d = 2.0 * sim.membrane.equivalentRadius();
    return {d, d, sim.membrane.height};
  }
  return {sim.box.length(0), sim.box.length(1), sim.box.length(2)};
}

double voidRatio(const Simulation& sim) { return sim.volume() / sim.particles.solidVolume() - 1.0; }

std::vector<int> contactsPerParticle(const Simulation& sim) {
  std::vector<int> contacts(sim.particles.size(), 0);
  forEachTouchingContact(sim, [&](const ContactView& c) {
    ++contacts[c.a];
    if (!c.wall) ++contacts[c.b];
  });
  return contacts;
}

double coordinationNumber(const Simulation& sim) {
  return 2.0 * static_cast<double>(sim.touchingPairs()) / static_cast<double>(sim.particles.size());
}

double kineticEnergy(const Simulation& sim) {
  const auto& P = sim.particles;
  double e = 0.0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    // An ellipsoid's rotational energy is w . L / 2 with its (exact) angular momentum.
    const double rotation = P.shape[i] == Shape::Ellipsoid ? 0.5 * P.angularVelocity[i].dot(P.angularMomentum[i])
                                                           : 0.5 * P.inertia[i] * P.angularVelocity[i].squaredNorm();
    e += 0.5 * P.mass[i] * P.velocity[i].squaredNorm() + rotation;
  }
  return e;
}

double elasticEnergy(const Simulation& sim) {
  double e = 0.0;
  forEachTouchingContact(sim, [&](const ContactView& c) {
    const contact::PairParams& pp = c.params;
    double u = c.normalEnergy;
    if (pp.ks > 0.0) u += 0.5 * c.history->shearForce.squaredNorm() / pp.ks;
    if (pp.kr > 0.0) u += 0.5 * c.history->moment.squaredNorm() / pp.kr;
    e += u;
  });
  return e;
}

}  // namespace grainlab::lab

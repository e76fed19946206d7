#pragma once
// A read-only view of the touching contacts of every pair kind, for measurements, snapshots and the
// micromechanical analysis (not for the hot loop): one visitor instead of a loop per kind and
// boundary in every client.
#include "core/simulation.hpp"

namespace grainlab {

struct ContactView {
  std::uint32_t a = 0;  // particle index
  std::uint32_t b = 0;  // particle index, or wall index for a wall contact
  bool wall = false;
  // Pairs: force of a on b. Walls: force of the wall on particle a.
  Vec3 force = Vec3::Zero();
  Vec3 normal = Vec3::Zero();  // pairs: from a to b; walls: the wall's inward normal (into a)
  // Pairs: x_b (its periodic image, when the contact crosses a face) - x_a. Walls: contact point - x_a.
  Vec3 branch = Vec3::Zero();
  // Contact point minus the centre of a and of b (for a wall only armA is meaningful).
  Vec3 armA = Vec3::Zero(), armB = Vec3::Zero();
  double overlap = 0.0;  // [m]
  contact::PairParams params{};
  const contact::ContactHistory* history = nullptr;
};

// Calls f(const ContactView&) for every touching contact, kind by kind in the store's order, each
// list in its (sorted) order.
template <class F>
void forEachTouchingContact(const Simulation& sim, F&& f) {
  const Particles& P = sim.particles;
  const auto& x = P.position;
  const auto& r = P.radius;
  const auto& mu = P.rollingFriction;
  const auto& pairs = sim.contacts.sphereSphere;
  for (std::size_t c = 0; c < pairs.size(); ++c) {
    if (!pairs.history[c].touching) continue;
    ContactView v;
    v.a = pairs.a[c];
    v.b = pairs.b[c];
    v.force = pairs.force[c];
    v.branch = x[v.b] - x[v.a];
    if (sim.boundary == Boundary::Periodic) v.branch += sim.cell.shiftVector(pairs.shift[c]);
    const double dist = v.branch.norm();
    v.overlap = r[v.a] + r[v.b] - dist;
    v.normal = v.branch / dist;
    v.armA = (r[v.a] - 0.5 * v.overlap) * v.normal;
    v.armB = v.armA - v.branch;
    v.params = sim.model.pairParams(r[v.a], r[v.b], mu[v.a], mu[v.b]);
    v.history = &pairs.history[c];
    f(static_cast<const ContactView&>(v));
  }
  const auto& walls = sim.contacts.sphereWall;
  for (std::size_t c = 0; c < walls.size(); ++c) {
    if (!walls.history[c].touching) continue;
    ContactView v;
    v.a = walls.a[c];
    v.b = walls.b[c];
    v.wall = true;
    const Wall& wall = sim.box.walls[v.b];
    v.force = walls.force[c];
    v.normal = wall.inwardNormal();
    const double gap = wall.distance(x[v.a]);
    v.overlap = r[v.a] - gap;
    v.branch = -(r[v.a] - 0.5 * v.overlap) * v.normal;
    v.armA = v.branch;
    v.params = sim.model.wallParams(r[v.a], wall.tanFriction, mu[v.a]);
    v.history = &walls.history[c];
    f(static_cast<const ContactView&>(v));
  }
}

}  // namespace grainlab

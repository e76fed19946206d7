#pragma once
// A read-only view of the touching contacts of every pair kind, for measurements, snapshots and the
// micromechanical analysis (not for the hot loop): one visitor instead of a loop per kind and
// boundary in every client.
#include "core/simulation.hpp"
#include "geometry/ellipsoid_contacts.hpp"

namespace grainlab {

struct ContactView {
  std::uint32_t a = 0;  // particle index
  std::uint32_t b = 0;  // particle index, or wall index for a wall contact
  bool wall = false;
  // Pairs: force of a on b. Walls: force of the wall on particle a.
  Vec3 force = Vec3::Zero();
  Vec3 normal = Vec3::Zero();  // pairs: from a to b; walls: the wall's inward normal (into a)
  // Pairs: x_b (its periodic image, when the contact crosses a face) - x_a. Walls: contact point - x_a.
  // (For an ellipsoid pair armA - armB = branch, but the arms are not along the normal.)
  Vec3 branch = Vec3::Zero();
  // Contact point minus the centre of a and of b (for a wall only armA is meaningful).
  Vec3 armA = Vec3::Zero(), armB = Vec3::Zero();
  double overlap = 0.0;  // [m] force-equivalent: Fn = kn overlap (Hertz–Mindlin: Fn = hertz overlap^(3/2))
  // Energy stored in the normal spring [J]: kn overlap^2 / 2 (Hertz: 2/5 Fn overlap), or for an
  // ellipsoid pair the potential of its contact function (docs/ellipsoids.md).
  double normalEnergy = 0.0;
  contact::PairParams params{};  // Hertz–Mindlin: resolved at the overlap (tangent stiffnesses)
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
    contact::SphereContactModel::resolve(v.params, v.overlap);
    v.normalEnergy = contact::SphereContactModel::normalEnergy(v.params, v.overlap);
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
    contact::SphereContactModel::resolve(v.params, v.overlap);
    v.normalEnergy = contact::SphereContactModel::normalEnergy(v.params, v.overlap);
    v.history = &walls.history[c];
    f(static_cast<const ContactView&>(v));
  }
  if (!P.anyEllipsoid()) return;
  // Ellipsoid kinds: the geometry again from the kernels, warm-started from the contact's lambda
  // and with its frozen potential length, so it is the geometry the law saw.
  const auto& req = P.equivalentRadius;
  auto shapeOf = [&](std::uint32_t i) { return geometry::shapeMatrix(P.semiAxes[i], P.orientation[i]); };
  auto pairView = [&](const auto& list, std::size_t c, const geometry::EllipsoidContact& e) {
    ContactView v;
    v.a = list.a[c];
    v.b = list.b[c];
    v.force = list.force[c];
    v.branch = x[v.b] - x[v.a];
    if (sim.boundary == Boundary::Periodic) v.branch += sim.cell.shiftVector(list.shift[c]);
    v.normal = e.geometry.normal;
    v.overlap = e.geometry.overlap;
    v.armA = e.geometry.branchA;
    v.armB = e.geometry.branchB;
    v.params = sim.model.pairParams(req[v.a], req[v.b], mu[v.a], mu[v.b]);
    v.normalEnergy = v.params.kn * e.energyOverKn;
    v.history = &list.history[c];
    return v;
  };
  const auto& ee = sim.contacts.ellipsoidEllipsoid;
  for (std::size_t c = 0; c < ee.size(); ++c) {
    const auto& h = ee.history[c];
    if (!h.touching) continue;
    Vec3 branch = x[ee.b[c]] - x[ee.a[c]];
    if (sim.boundary == Boundary::Periodic) branch += sim.cell.shiftVector(ee.shift[c]);
    const geometry::EllipsoidContact e =
        geometry::ellipsoidEllipsoid(branch, shapeOf(ee.a[c]), shapeOf(ee.b[c]), h.lambda, h.potentialLength);
    if (e.touching) f(static_cast<const ContactView&>(pairView(ee, c, e)));
  }
  const auto& se = sim.contacts.sphereEllipsoid;
  for (std::size_t c = 0; c < se.size(); ++c) {
    const auto& h = se.history[c];
    if (!h.touching) continue;
    Vec3 branch = x[se.b[c]] - x[se.a[c]];
    if (sim.boundary == Boundary::Periodic) branch += sim.cell.shiftVector(se.shift[c]);
    const geometry::EllipsoidContact e =
        geometry::sphereEllipsoid(branch, r[se.a[c]], P.semiAxes[se.b[c]], P.orientation[se.b[c]], h.lambda,
                                  h.potentialLength);
    if (e.touching) f(static_cast<const ContactView&>(pairView(se, c, e)));
  }
  const auto& ew = sim.contacts.ellipsoidWall;
  for (std::size_t c = 0; c < ew.size(); ++c) {
    if (!ew.history[c].touching) continue;
    ContactView v;
    v.a = ew.a[c];
    v.b = ew.b[c];
    v.wall = true;
    const Wall& wall = sim.box.walls[v.b];
    Vec3 point = x[v.a];
    point[wall.axis] = wall.position;
    const geometry::EllipsoidPlaneContact e = geometry::ellipsoidPlane(x[v.a], shapeOf(v.a), point, wall.inwardNormal());
    v.force = ew.force[c];
    v.normal = wall.inwardNormal();
    v.overlap = e.geometry.overlap;
    v.branch = e.geometry.branchB;
    v.armA = v.branch;
    v.params = sim.model.wallParams(req[v.a], wall.tanFriction, mu[v.a]);
    v.normalEnergy = v.params.kn * e.energyOverKn;
    v.history = &ew.history[c];
    f(static_cast<const ContactView&>(v));
  }
}

}  // namespace grainlab

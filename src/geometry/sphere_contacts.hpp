#pragma once
// Narrow phase for spheres (docs/physics.md §3): pure functions, no storage.
#include <cmath>

#include "core/types.hpp"

namespace grainlab::geometry {

// Geometry of one contact. `normal` points from A to B; `branchA` = C - X_A, `branchB` = C - X_B.
struct ContactGeometry {
  Vec3 normal;
  double overlap;  // U > 0 when touching [m]
  Vec3 branchA;
  Vec3 branchB;
};

// Sphere A at xA (radius rA) against sphere B at xB (radius rB), given the branch xB - xA and
// its squared length (already computed by the caller's distance test).
inline ContactGeometry sphereSphere(const Vec3& branch, double dist2, double rA, double rB) {
  const double dist = std::sqrt(dist2);
  ContactGeometry g;
  g.normal = branch * (1.0 / dist);
  g.overlap = rA + rB - dist;
  // C = X_A + (R_A - U/2) N
  g.branchA = (rA - 0.5 * g.overlap) * g.normal;
  g.branchB = g.branchA - branch;
  return g;
}

// A sphere (body B) against a plane (body A) through `planePoint` with unit `inwardNormal`
// pointing into the half-space where the sphere lives. branchA is left as the vector from
// the plane point to C (only branchB is physical for a body of infinite radius).
inline ContactGeometry spherePlane(const Vec3& x, double r, const Vec3& planePoint,
                                   const Vec3& inwardNormal) {
  const double gap = (x - planePoint).dot(inwardNormal);
  ContactGeometry g;
  g.normal = inwardNormal;
  g.overlap = r - gap;
  g.branchB = -(r - 0.5 * g.overlap) * inwardNormal;
  g.branchA = x + g.branchB - planePoint;
  return g;
}

}  // namespace grainlab::geometry

#pragma once
// Critical time step of an ellipsoid held by its stiffest contact (docs/physics.md §7), including the
// rotational stiffness that elongation adds (docs/ellipsoids.md, "Critical time step").
#include <algorithm>
#include <cmath>

#include "core/types.hpp"

namespace grainlab::geometry {

// Largest arms of a unit normal contact force about the body axes x, y, z (torque component along
// each axis): b - c, a - c, a - b. About body axis x the torque is that of the force's projection
// on the y-z plane, which acts along the normal of the ellipse (b, c) scaled through the contact
// point, whose normal lines pass within b - c of the centre (the 2D ellipse's a - b, attained at
// tan^2 t = b/a); likewise for the other axes. A sphere's normal forces have no arm;
// Perram–Wertheim forces act along the normal of the body scaled by sqrt(F) < 1 through the
// contact point, so their arms are smaller still.
inline Vec3 maxNormalForceArms(const Vec3& s) { return {s.y() - s.z(), s.x() - s.z(), s.x() - s.y()}; }
// Largest distance of a surface point from each body axis: the arm of a tangential force.
inline Vec3 maxTangentialForceArms(const Vec3& s) { return {s.y(), s.x(), s.x()}; }

// Factor by which the potential's normal stiffness exceeds kn at a contact of support sum H when
// the potential length is L: the force-equivalent overlap is (L/H)^2 times the geometric depth.
// With the frozen-length policy it is 1 when the contact forms; with the pair-constant policy
// L = rA + rB (equivalent radii) it is at most (L/H_min)^2 with H_min = cA + cB (a plane: c).
inline double potentialStiffnessFactor(double potentialLength, double minSupportSum) {
  const double f = potentialLength / minSupportSum;
  return f * f;
}

// min( sqrt(m/kn), min over body axes k of sqrt(I_k / k_theta,k) ), with the rotational stiffness
// of one contact about body axis k, k_theta,k = kn arm_k^2 + ks reach_k^2 + kr (normal spring at
// its largest arm about k, shear spring at the largest distance from k, rolling spring). For a
// sphere this is the engine's estimate sqrt(I/(ks r^2 + kr)). kn is the largest effective normal
// stiffness (times potentialStiffnessFactor for ellipsoid pairs). The per-axis form is 1.8x
// larger than pairing the smallest inertia with the largest arms (a - c, a) for a 3:1.5:1 grain,
// and still safe: checked in the tests against the largest eigenfrequency of the six-degree-of-
// freedom stiffness of a contact, dt_c w_max <= 1.1 over random orientations (leapfrog needs < 2).
inline double ellipsoidCriticalTimeStep(double mass, const Vec3& inertia, const Vec3& semiAxes, double kn,
                                        double ks, double kr) {
  const Vec3 arm = maxNormalForceArms(semiAxes), reach = maxTangentialForceArms(semiAxes);
  double dt = std::sqrt(mass / kn);
  for (int k = 0; k < 3; ++k) {
    const double kTheta = kn * arm[k] * arm[k] + ks * reach[k] * reach[k] + kr;
    if (kTheta > 0.0) dt = std::min(dt, std::sqrt(inertia[k] / kTheta));
  }
  return dt;
}

}  // namespace grainlab::geometry

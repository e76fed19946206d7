#pragma once
// Critical time step of an ellipsoid held by its stiffest contact (PHYSICS.md §4), including the
// rotational stiffness that elongation adds (docs/ellipsoids.md, "Critical time step").
#include <algorithm>
#include <cmath>

#include "core/types.hpp"

namespace grainlab::geometry {

// Largest arm of a normal contact force about the centre: the distance from the centre to a
// normal line of the surface is at most a - c (the 2D ellipse's a - b, attained in the a-c
// plane). A sphere's normal forces have no arm. Perram–Wertheim forces act along the normal of
// the body scaled by sqrt(F) < 1 at the contact point, so their arm is smaller still.
inline double maxNormalForceArm(const Vec3& semiAxes) { return semiAxes.x() - semiAxes.z(); }

// Factor by which the potential's normal stiffness exceeds kn at a contact of support sum H when
// the potential length is L: the force-equivalent overlap is (L/H)^2 times the geometric depth.
// With the frozen-length policy it is 1 when the contact forms; with the pair-constant policy
// L = rA + rB (equivalent radii) it is at most (L/H_min)^2 with H_min = cA + cB (a plane: c).
inline double potentialStiffnessFactor(double potentialLength, double minSupportSum) {
  const double f = potentialLength / minSupportSum;
  return f * f;
}

// min( sqrt(m/kn), sqrt(I_min/k_theta) ), k_theta = kn (a - c)^2 + ks a^2 + kr: the rotational
// stiffness of one contact about the axis of least inertia, the normal spring at its largest
// arm a - c, the shear spring at the largest branch a. For a sphere (a = c) this is the
// engine's estimate sqrt(I/(ks r^2 + kr)). kn is the largest effective normal stiffness (times
// potentialStiffnessFactor for ellipsoid pairs). Checked in the tests against the largest
// eigenfrequency of the six-degree-of-freedom contact stiffness: dt_c w_max < 2.
inline double ellipsoidCriticalTimeStep(double mass, const Vec3& inertia, const Vec3& semiAxes, double kn,
                                        double ks, double kr) {
  const double a = semiAxes.maxCoeff();
  const double arm = maxNormalForceArm(semiAxes);
  const double kTheta = kn * arm * arm + ks * a * a + kr;
  return std::min(std::sqrt(mass / kn), std::sqrt(inertia.minCoeff() / kTheta));
}

}  // namespace grainlab::geometry

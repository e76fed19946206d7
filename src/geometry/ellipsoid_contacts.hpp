#pragma once
// Narrow phase for ellipsoids (docs/physics.md §3; derivations in docs/ellipsoids.md): pure functions,
// no storage. Contacts between ellipsoids (and a sphere and an ellipsoid) come from the
// Perram–Wertheim contact function [PW85]
//     F(A, B) = max over lambda in [0, 1] of S(lambda),
//     S(lambda) = lambda (1 - lambda) R^T G(lambda)^-1 R,   G = (1 - lambda) X_A + lambda X_B,
// with R = x_B - x_A and X the shape matrices (ellipsoid_shape.hpp). sqrt(F) is the factor by
// which both bodies, scaled about their centres, just touch: they overlap iff F < 1. S is concave
// with S(0) = S(1) = 0, so its maximiser is unique; it is found by a warm-started, bracketed
// Newton iteration.
//
// The normal force derives from the potential U = kn L^2 (1 - sqrt F)^2 / 2 (L a length fixed for
// the life of the contact). Because dF/dt = 2 lambda (1 - lambda) p . v_rel(C) with p = G^-1 R and
// C the Perram–Wertheim point [DTS05], -grad U is one force kn * overlap * n along n = p/|p|
// through C, with the force-equivalent overlap
//     overlap = L^2 (1 - sqrt F) / H,   H = h_A(n) + h_B(n)  (support distances along n),
// so a frictionless undamped collision conserves energy exactly (in continuous time), torques
// included. The geometric depth H (1 - sqrt F) = h_A(n) + h_B(n) - n.R is returned for reporting;
// it equals `overlap` when L = H.
#include <cmath>
#include <limits>

#include "geometry/ellipsoid_shape.hpp"
#include "geometry/sphere_contacts.hpp"

// The kernels are forced inline into the contact loops, as the sphere law is (contact/models.hpp):
// called out of line, the solve's result went through the stack (profile of the micro-benchmark).
#if defined(__GNUC__)
#define GRAINLAB_ELLIPSOID_INLINE inline __attribute__((always_inline))
#else
#define GRAINLAB_ELLIPSOID_INLINE inline
#endif

namespace grainlab::geometry {

// One ellipsoid contact. `geometry` has the engine's meaning (sphere_contacts.hpp): unit normal
// from A to B, the force-equivalent overlap (Fn = kn * overlap, > 0 when touching) and the
// branches from each centre to the contact point. When !touching only `contactFunction` (then a
// lower bound >= 1 of F when the solve stopped early) and `lambda` are meaningful; the rest is 0.
struct EllipsoidContact {
  ContactGeometry geometry{Vec3::Zero(), 0.0, Vec3::Zero(), Vec3::Zero()};
  bool touching = false;
  double contactFunction = 0.0;  // F (PW85)
  double lambda = 0.0;           // maximiser of S: keep it in the contact history (warm start)
  double potentialLength = 0.0;  // the L the overlap was computed with [m]
  double energyOverKn = 0.0;     // normal spring energy / kn = L^2 (1 - sqrt F)^2 / 2 [m^2]
  double depth = 0.0;            // geometric overlap h_A(n) + h_B(n) - n.R [m] (reporting)
  double supportSum = 0.0;       // H = h_A(n) + h_B(n) [m]
  int iterations = 0;            // evaluations of S in the solve
  bool converged = false;        // false only if the iteration limit was hit (never seen in tests)
};

namespace pw {

// Newton steps shorter than this stop the solve; the result is then extrapolated to the
// maximiser to third order in the step, which leaves errors of order 1e-15 relative (measured in
// the tests against an independent fully converged solve). With warm starts in quasi-static
// runs lambda moves by ~1e-6 per step, so most solves take one evaluation of S.
constexpr double kStepTolerance = 1e-5;
constexpr int kNewtonIterations = 30;  // then bisection only
constexpr int kMaxIterations = 100;

// S and its derivatives at lambda from p = G^-1 R, D p, q = G^-1 D p (D = X_B - X_A):
//   a0 = R.p, a1 = p.Dp, a2 = Dp.q, a3 = q.Dq,
//   S = w a0, S' = (1 - 2 lambda) a0 - w a1, S'' = -2 a0 - 2 (1 - 2 lambda) a1 + 2 w a2,
//   S''' = 6 (a1 + (1 - 2 lambda) a2 - w a3),
// with w = lambda (1 - lambda), from dG^-1/dlambda = -G^-1 D G^-1 (so a0' = -a1, a1' = -2 a2,
// a2' = -3 a3) and dp/dlambda = -q.
struct PencilValues {
  Vec3 p, q;
  double a0, a1, a2;
};

// The pencil in world coordinates: shape matrices X_A and D = X_B - X_A.
struct GeneralPencil {
  Sym3 xa, d;
  Vec3 r;
  struct Eval : PencilValues {
    Sym3 adj;
    double invDet;
  };
  GRAINLAB_ELLIPSOID_INLINE Eval operator()(double lambda) const {
    Eval e;
    const Sym3 g = xa + d * lambda;
    e.adj = g.adjugate();
    // The products run on the adjugate and the scaling by 1/det comes last, so that the
    // division overlaps the matrix-vector products instead of preceding them (latency).
    e.invDet = 1.0 / g.determinant(e.adj);
    const Vec3 pa = e.adj * r;  // det p
    const Vec3 dpa = d * pa;    // det D p
    const Vec3 qa = e.adj * dpa;  // det^2 q
    const double i2 = e.invDet * e.invDet;
    e.p = pa * e.invDet;
    e.q = qa * i2;
    e.a0 = r.dot(pa) * e.invDet;
    e.a1 = pa.dot(dpa) * i2;
    e.a2 = dpa.dot(qa) * (i2 * e.invDet);
    return e;
  }
  Vec3 timesD(const Vec3& v) const { return d * v; }
  Vec3 solve(const Eval& e, const Vec3& v) const { return (e.adj * v) * e.invDet; }  // G^-1 v
  // Cold start: the sphere value h_A/(h_A + h_B) with the support distances along R (exact for
  // spheres, so the sphere limit needs one evaluation).
  double coldStart() const {
    const double ha = std::sqrt(xa.quadratic(r)), hb = std::sqrt((xa + d).quadratic(r));
    return ha / (ha + hb);
  }
};

// The pencil in a frame where both matrices are diagonal: a sphere (X_A = r^2 I) against an
// ellipsoid, in the ellipsoid's body frame. Every evaluation is then three divisions.
struct DiagonalPencil {
  Vec3 xa, d;  // diagonals of X_A and D
  Vec3 r;
  struct Eval : PencilValues {
    Vec3 invG;
  };
  GRAINLAB_ELLIPSOID_INLINE Eval operator()(double lambda) const {
    Eval e;
    e.invG = (xa + lambda * d).cwiseInverse();
    e.p = r.cwiseProduct(e.invG);
    const Vec3 dp = d.cwiseProduct(e.p);
    e.q = dp.cwiseProduct(e.invG);
    e.a0 = r.dot(e.p);
    e.a1 = e.p.dot(dp);
    e.a2 = dp.dot(e.q);
    return e;
  }
  Vec3 timesD(const Vec3& v) const { return d.cwiseProduct(v); }
  Vec3 solve(const Eval& e, const Vec3& v) const { return v.cwiseProduct(e.invG); }
  double coldStart() const {
    const Vec3 r2 = r.cwiseProduct(r);
    const double ha = std::sqrt(xa.dot(r2)), hb = std::sqrt((xa + d).dot(r2));
    return ha / (ha + hb);
  }
};

struct Solution {
  double lambda = 0.0;
  double contactFunction = 0.0;  // F, or the first S(lambda) >= 1 when stopped as apart
  Vec3 p = Vec3::Zero();         // G(lambda)^-1 R
  int iterations = 0;
  bool converged = false;
  bool apart = false;  // stopped early: S(lambda) >= 1 proves F >= 1
};

// Maximises S over [0, 1]. lambdaStart in (0, 1) warm-starts (the lambda of the previous step);
// anything else (0 for a new contact, NaN) starts cold. The bracket [lo, hi] always holds the
// maximiser (S'(lo) > 0 > S'(hi)); a Newton step that leaves it, or that is tried after
// kNewtonIterations, is replaced by bisection, so the solve cannot diverge. With stopWhenApart,
// the first S(lambda) >= 1 ends it: F >= S(lambda) for every lambda, so the bodies are apart.
template <class Pencil>
GRAINLAB_ELLIPSOID_INLINE Solution maximise(const Pencil& pencil, double lambdaStart, bool stopWhenApart) {
  Solution sol;
  double lo = 0.0, hi = 1.0;
  double lambda = lambdaStart > 0.0 && lambdaStart < 1.0 ? lambdaStart : pencil.coldStart();
  for (int it = 1; it <= kMaxIterations; ++it) {
    const auto e = pencil(lambda);
    const double w = lambda * (1.0 - lambda);
    const double s = w * e.a0;
    sol.iterations = it;
    sol.lambda = lambda;
    sol.contactFunction = s;
    sol.p = e.p;
    if (stopWhenApart && s >= 1.0) {
      sol.apart = true;
      sol.converged = true;
      return sol;
    }
    const double ds = (1.0 - 2.0 * lambda) * e.a0 - w * e.a1;
    const double d2s = -2.0 * e.a0 - 2.0 * (1.0 - 2.0 * lambda) * e.a1 + 2.0 * w * e.a2;
    if (ds > 0.0) lo = lambda; else hi = lambda;
    const double invD2s = 1.0 / d2s;
    const double step = -ds * invD2s;
    const double next = lambda + step;
    const bool newton = it <= kNewtonIterations && d2s < 0.0;
    if (newton && std::abs(step) <= kStepTolerance) {
      // Converged (S concave, the Newton step tiny; it may be below one ulp of lambda). The
      // Newton point itself is off by O(step^2), which would tilt the normal by ~1e-10 at a step
      // of 1e-5; the step is corrected with S''' (a root of the quadratic Taylor model of S',
      // Halley-like) and p, F extrapolated to it, all to O(step^3).
      const Vec3 dq = pencil.timesD(e.q);
      const double a3 = e.q.dot(dq);
      const double d3sOver6 = e.a1 + (1.0 - 2.0 * lambda) * e.a2 - w * a3;  // S'''/6
      const double delta = step - 3.0 * d3sOver6 * invD2s * step * step;
      sol.lambda = lambda + delta;
      sol.p = e.p + delta * (delta * pencil.solve(e, dq) - e.q);
      sol.contactFunction = s + delta * (ds + delta * (0.5 * d2s + delta * d3sOver6));
      sol.converged = true;
      return sol;
    }
    lambda = newton && next > lo && next < hi ? next : 0.5 * (lo + hi);
    if (hi - lo <= 4.0 * std::numeric_limits<double>::epsilon()) {  // bracket at round-off
      sol.converged = true;
      return sol;
    }
  }
  return sol;
}

// From the solved pencil to the contact. p = G^-1 R at the maximiser, in world coordinates or in
// a body frame that `toWorld` rotates to world (then n = toWorld p/|p|); bPW = (1 - lambda) X_A p:
// the Perram–Wertheim point relative to x_A, in world coordinates. At the maximiser
// (1 - lambda)^2 p.X_A p = lambda^2 p.X_B p = F (S' = 0), so the PW point lies on both bodies scaled by sqrt F, with normal n, and the
// support distances along n come without another quadratic form:
//     h_A = sqrt(n.X_A n) = sqrt(F)/((1 - lambda)|p|),   h_B = sqrt(F)/(lambda |p|).
// The force line is n through the PW point; the contact point is moved along that line (which
// changes no torque of the normal force) to midway between the two support planes, where the
// sphere kernel puts it: n.(C - x_A) = (h_A - h_B + n.R)/2.
GRAINLAB_ELLIPSOID_INLINE void assemble(EllipsoidContact& c, const Vec3& r, const Vec3& p, const Quat* toWorld, const Vec3& bPW,
                     double potentialLength) {
  const double sqrtF = std::sqrt(c.contactFunction);
  const double pNorm = p.norm();
  const double w = c.lambda * (1.0 - c.lambda);
  // One division serves 1/|p|, H and 1/H: with inv = 1/(|p| sqrt(F) w),
  // 1/|p| = sqrt(F) w inv, H = sqrt(F)/(|p| w) = F inv, 1/H = (|p| w)^2 inv.
  const double inv = 1.0 / (pNorm * sqrtF * w);
  const double invNorm = sqrtF * w * inv;
  const double h = c.contactFunction * inv;
  const double invH = (pNorm * w) * (pNorm * w) * inv;
  const double ha = c.lambda * h, hb = (1.0 - c.lambda) * h;
  const double gap = 1.0 - sqrtF;  // > 0: overlapping
  const double l = potentialLength > 0.0 ? potentialLength : h;
  const Vec3 n = toWorld ? (*toWorld) * (p * invNorm) : Vec3(p * invNorm);
  c.touching = true;
  c.supportSum = h;
  c.depth = h * gap;
  c.potentialLength = l;
  c.geometry.normal = n;
  c.geometry.overlap = l * l * gap * invH;
  c.energyOverKn = 0.5 * l * l * gap * gap;
  const double along = 0.5 * (ha - hb + n.dot(r));
  c.geometry.branchA = bPW + (along - n.dot(bPW)) * n;
  c.geometry.branchB = c.geometry.branchA - r;
}

// The solve's part of a contact (all of it when the pair is apart).
inline EllipsoidContact solveRecord(const Solution& s) {
  EllipsoidContact c;
  c.lambda = s.lambda;
  c.contactFunction = s.contactFunction;
  c.iterations = s.iterations;
  c.converged = s.converged;
  return c;
}

// Coincident centres: S vanishes for every lambda and no normal is defined. Report a deep contact
// along world z rather than NaN (the engine should never get there; a sane time step forbids it).
inline EllipsoidContact coincidentCentres(double ha, double hb, double potentialLength) {
  EllipsoidContact c;
  const double h = ha + hb;
  const double l = potentialLength > 0.0 ? potentialLength : h;
  c.touching = true;
  c.converged = true;
  c.lambda = ha / h;
  c.supportSum = h;
  c.depth = h;
  c.potentialLength = l;
  c.geometry.normal = Vec3::UnitZ();
  c.geometry.overlap = l * l / h;
  c.energyOverKn = 0.5 * l * l;
  c.geometry.branchA = 0.5 * (ha - hb) * Vec3::UnitZ();
  c.geometry.branchB = c.geometry.branchA;
  return c;
}

}  // namespace pw

// Ellipsoid A against ellipsoid B (either may be a sphere, X = r^2 I). branch = x_B - x_A; xa, xb
// their shape matrices; lambdaPrev the lambda kept from the previous step (0 for a new pair);
// potentialLength the L of the potential: > 0 uses that value, <= 0 uses the current support sum
// H (what the engine passes on the first touching step under the frozen-length policy, then
// keeps result.potentialLength). Swapping A and B flips the normal and gives lambda -> 1 - lambda,
// the same overlap and the same contact point.
GRAINLAB_ELLIPSOID_INLINE EllipsoidContact ellipsoidEllipsoid(const Vec3& branch, const Sym3& xa, const Sym3& xb,
                                           double lambdaPrev, double potentialLength) {
  if (branch.squaredNorm() == 0.0) {
    return pw::coincidentCentres(std::sqrt(xa.zz), std::sqrt(xb.zz), potentialLength);
  }
  const pw::GeneralPencil pencil{xa, xb - xa, branch};
  const pw::Solution s = pw::maximise(pencil, lambdaPrev, true);
  EllipsoidContact c = pw::solveRecord(s);
  if (s.apart || !(s.contactFunction < 1.0)) return c;
  pw::assemble(c, branch, s.p, nullptr, (1.0 - s.lambda) * (xa * s.p), potentialLength);
  return c;
}

// Sphere A (radius ra) against ellipsoid B (semi-axes, orientation qb), solved in B's body frame
// where both shape matrices are diagonal (a specialised evaluation of the same contact function:
// results agree with ellipsoidEllipsoid(branch, ra^2 I, X_B, ...) to round-off).
GRAINLAB_ELLIPSOID_INLINE EllipsoidContact sphereEllipsoid(const Vec3& branch, double ra, const Vec3& semiAxesB,
                                        const Quat& qb, double lambdaPrev, double potentialLength) {
  if (branch.squaredNorm() == 0.0) {
    return pw::coincidentCentres(ra, std::sqrt(shapeMatrix(semiAxesB, qb).zz), potentialLength);
  }
  const Vec3 rBody = qb.conjugate() * branch;
  const Vec3 xa = Vec3::Constant(ra * ra);
  const Vec3 xb = semiAxesB.cwiseProduct(semiAxesB);
  const pw::DiagonalPencil pencil{xa, xb - xa, rBody};
  const pw::Solution s = pw::maximise(pencil, lambdaPrev, true);
  EllipsoidContact c = pw::solveRecord(s);
  if (s.apart || !(s.contactFunction < 1.0)) return c;
  pw::assemble(c, branch, s.p, &qb, qb * ((1.0 - s.lambda) * ra * ra * s.p), potentialLength);
  return c;
}

// F without the early stop (a separation measure for tests and diagnostics).
inline pw::Solution contactFunction(const Vec3& branch, const Sym3& xa, const Sym3& xb, double lambdaStart = 0.0) {
  return pw::maximise(pw::GeneralPencil{xa, xb - xa, branch}, lambdaStart, false);
}

// An ellipsoid (body B, centre x, shape matrix X) against a plane (body A) through `planePoint`
// with unit `inwardNormal` m pointing into the ellipsoid's half-space; conventions of
// spherePlane. Closed form: the deepest point is the support point x - X m/h, h = sqrt(m^T X m),
// and the overlap h - (x - P).m is exactly geometric. U = kn overlap^2 / 2 is a potential whose
// gradient is the force kn overlap m through the support point (dh/dtheta = (X m x m)/h . dtheta),
// so the wall contact conserves energy too; C is moved along m to the middle of the overlap.
struct EllipsoidPlaneContact {
  ContactGeometry geometry;
  double energyOverKn;  // overlap^2 / 2 [m^2] (0 when apart)
  bool touching;
};

inline EllipsoidPlaneContact ellipsoidPlane(const Vec3& x, const Sym3& shape, const Vec3& planePoint,
                                            const Vec3& inwardNormal) {
  const Vec3 xm = shape * inwardNormal;
  const double h = std::sqrt(inwardNormal.dot(xm));
  EllipsoidPlaneContact c;
  c.geometry.normal = inwardNormal;
  c.geometry.overlap = h - (x - planePoint).dot(inwardNormal);
  c.touching = c.geometry.overlap > 0.0;
  c.energyOverKn = c.touching ? 0.5 * c.geometry.overlap * c.geometry.overlap : 0.0;
  c.geometry.branchB = (0.5 * c.geometry.overlap) * inwardNormal - xm * (1.0 / h);
  c.geometry.branchA = x + c.geometry.branchB - planePoint;
  return c;
}

// Cheap conservative filters for candidates of the broad phase; neither ever rejects a touching
// pair. Bounding spheres (radius a of each body):
inline bool boundingSpheresOverlap(const Vec3& branch, double reachA, double reachB) {
  return branch.squaredNorm() < (reachA + reachB) * (reachA + reachB);
}
// Separating axis along the line of centres: the support distances along R-hat do not reach
// across, h_A + h_B <= |R| (written unnormalised: sqrt(R^T X_A R) + sqrt(R^T X_B R) <= R.R).
// Exact for spheres, and it prunes side-by-side elongated grains the bounding spheres accept.
inline bool separatedAlongCentreLine(const Vec3& branch, const Sym3& xa, const Sym3& xb) {
  return std::sqrt(xa.quadratic(branch)) + std::sqrt(xb.quadratic(branch)) <= branch.squaredNorm();
}

}  // namespace grainlab::geometry

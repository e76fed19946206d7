// Ellipsoid contact kernels (ellipsoid_contacts.hpp) against independent numbers: the sphere
// kernels, a brute-force maximisation with dense solves, exact aligned cases, finite differences
// of the potential, the work around closed loops, and brute-force contact detection.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include "geometry/ellipsoid_contacts.hpp"
#include "geometry/sphere_contacts.hpp"
#include "test_ellipsoid_helpers.hpp"

using namespace grainlab;
using namespace grainlab::geometry;
using grainlab::etest::randomRotation;
using grainlab::etest::randomSemiAxes;
using grainlab::etest::randomUnitVector;

namespace {

// B's centre offset along u at which A (at the origin) and B just touch: F is homogeneous of
// degree 2 in R, so the touching distance along u is 1/sqrt(F(u)).
double touchingDistance(const Vec3& u, const Sym3& xa, const Sym3& xb) {
  return 1.0 / std::sqrt(contactFunction(u, xa, xb).contactFunction);
}

// A random overlapping configuration with relative overlap ~eps: R = u d_touch (1 - eps).
struct Config {
  Vec3 axesA, axesB;
  Quat qa, qb;
  Vec3 r;
  Sym3 xa() const { return shapeMatrix(axesA, qa); }
  Sym3 xb() const { return shapeMatrix(axesB, qb); }
};
Config randomConfig(std::mt19937_64& rng, double eps, double maxAspect = 3.0) {
  Config c{randomSemiAxes(rng, 1.0, maxAspect), randomSemiAxes(rng, 1.0, maxAspect), randomRotation(rng),
           randomRotation(rng), Vec3::Zero()};
  const Vec3 u = randomUnitVector(rng);
  c.r = u * touchingDistance(u, c.xa(), c.xb()) * (1.0 - eps);
  return c;
}

double scaleOf(const Config& c) { return c.axesA.x() + c.axesB.x(); }

}  // namespace

// a = b = c: every output equals the sphere kernel's to round-off, for both potential-length
// policies (frozen at H = rA + rB, or given as rA + rB), whatever the orientations.
TEST(EllipsoidSphereLimit, GeneralKernelEqualsSphereKernel) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0.2, 2.0), e(1e-6, 0.3);
  for (int trial = 0; trial < 1000; ++trial) {
    const double ra = u(rng), rb = u(rng);
    const Vec3 dir = randomUnitVector(rng);
    const Vec3 branch = dir * (ra + rb) * (1.0 - e(rng));
    const ContactGeometry ref = sphereSphere(branch, branch.squaredNorm(), ra, rb);
    const Sym3 xa = shapeMatrix(Vec3::Constant(ra), randomRotation(rng));
    const Sym3 xb = shapeMatrix(Vec3::Constant(rb), randomRotation(rng));
    for (double length : {0.0, ra + rb}) {
      const EllipsoidContact c = ellipsoidEllipsoid(branch, xa, xb, 0.0, length);
      const double tol = 1e-14 * (ra + rb);
      ASSERT_TRUE(c.touching);
      EXPECT_EQ(c.iterations, 1);  // the cold start is the sphere's exact lambda
      EXPECT_NEAR(c.lambda, ra / (ra + rb), 1e-14);
      EXPECT_LT((c.geometry.normal - ref.normal).norm(), 1e-14);
      EXPECT_NEAR(c.geometry.overlap, ref.overlap, tol);
      EXPECT_NEAR(c.depth, ref.overlap, tol);
      EXPECT_NEAR(c.energyOverKn, 0.5 * ref.overlap * ref.overlap, tol * ref.overlap);
      EXPECT_LT((c.geometry.branchA - ref.branchA).norm(), tol);
      EXPECT_LT((c.geometry.branchB - ref.branchB).norm(), tol);
    }
  }
}

TEST(EllipsoidSphereLimit, SphereEllipsoidAndPlaneKernelsEqualSphereKernels) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(0.2, 2.0), e(1e-6, 0.3);
  for (int trial = 0; trial < 1000; ++trial) {
    const double ra = u(rng), rb = u(rng);
    const Vec3 branch = randomUnitVector(rng) * (ra + rb) * (1.0 - e(rng));
    const ContactGeometry ref = sphereSphere(branch, branch.squaredNorm(), ra, rb);
    const EllipsoidContact c = sphereEllipsoid(branch, ra, Vec3::Constant(rb), randomRotation(rng), 0.0, 0.0);
    const double tol = 1e-14 * (ra + rb);
    ASSERT_TRUE(c.touching);
    EXPECT_LT((c.geometry.normal - ref.normal).norm(), 1e-14);
    EXPECT_NEAR(c.geometry.overlap, ref.overlap, tol);
    EXPECT_LT((c.geometry.branchA - ref.branchA).norm(), tol);
    EXPECT_LT((c.geometry.branchB - ref.branchB).norm(), tol);

    const Vec3 m = randomUnitVector(rng), p = randomUnitVector(rng);
    const Vec3 x = p + m * rb * (1.0 - e(rng));
    const ContactGeometry wref = spherePlane(x, rb, p, m);
    const EllipsoidPlaneContact w = ellipsoidPlane(x, shapeMatrix(Vec3::Constant(rb), randomRotation(rng)), p, m);
    ASSERT_TRUE(w.touching);
    EXPECT_NEAR(w.geometry.overlap, wref.overlap, tol);
    EXPECT_LT((w.geometry.branchA - wref.branchA).norm(), 4 * tol);
    EXPECT_LT((w.geometry.branchB - wref.branchB).norm(), tol);
  }
}

// The specialised sphere-ellipsoid evaluation (ellipsoid frame, diagonal pencil) is the same
// function as the general one with X_A = r^2 I.
TEST(EllipsoidContact, SphereEllipsoidEqualsGeneralSolve) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> e(1e-5, 0.2), rad(0.3, 2.0);
  for (int trial = 0; trial < 500; ++trial) {
    const double ra = rad(rng);
    const Vec3 axes = randomSemiAxes(rng, 1.0, 4.0);
    const Quat qb = randomRotation(rng);
    const Sym3 xa = Sym3::identity(ra * ra), xb = shapeMatrix(axes, qb);
    const Vec3 u = randomUnitVector(rng);
    const Vec3 branch = u * touchingDistance(u, xa, xb) * (1.0 - e(rng));
    const EllipsoidContact g = ellipsoidEllipsoid(branch, xa, xb, 0.0, 0.0);
    const EllipsoidContact s = sphereEllipsoid(branch, ra, axes, qb, 0.0, 0.0);
    ASSERT_TRUE(g.touching && s.touching);
    const double scale = ra + axes.x();
    EXPECT_NEAR(s.contactFunction, g.contactFunction, 1e-13);
    EXPECT_LT((s.geometry.normal - g.geometry.normal).norm(), 1e-11);
    EXPECT_NEAR(s.geometry.overlap, g.geometry.overlap, 1e-13 * scale);
    EXPECT_LT((s.geometry.branchA - g.geometry.branchA).norm(), 1e-11 * scale);
  }
}

// Coincident centres (no normal defined): a finite deep contact along z, never NaN.
TEST(EllipsoidContact, CoincidentCentresGiveAFiniteContact) {
  const Sym3 xa = shapeMatrix(Vec3(2, 1, 0.5), Quat::Identity()), xb = shapeMatrix(Vec3(1, 1, 1), Quat::Identity());
  const EllipsoidContact c = ellipsoidEllipsoid(Vec3::Zero(), xa, xb, 0.0, 0.0);
  EXPECT_TRUE(c.touching);
  EXPECT_EQ(c.geometry.normal, Vec3::UnitZ());
  EXPECT_DOUBLE_EQ(c.depth, 1.5);  // support distances along z: 0.5 + 1
  EXPECT_TRUE(c.geometry.branchA.allFinite() && std::isfinite(c.geometry.overlap));
  const EllipsoidContact s = sphereEllipsoid(Vec3::Zero(), 1.0, Vec3(2, 1, 0.5), Quat::Identity(), 0.0, 0.0);
  EXPECT_DOUBLE_EQ(s.depth, 1.5);
}

// Swapping A and B flips the normal, keeps overlap, depth and contact point, maps lambda to
// 1 - lambda.
TEST(EllipsoidContact, SwapSymmetry) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> e(1e-5, 0.2);
  for (int trial = 0; trial < 500; ++trial) {
    const Config c = randomConfig(rng, e(rng));
    const EllipsoidContact ab = ellipsoidEllipsoid(c.r, c.xa(), c.xb(), 0.0, 0.0);
    const EllipsoidContact ba = ellipsoidEllipsoid(-c.r, c.xb(), c.xa(), 0.0, 0.0);
    ASSERT_TRUE(ab.touching && ba.touching);
    const double s = scaleOf(c);
    EXPECT_LT((ab.geometry.normal + ba.geometry.normal).norm(), 1e-11);
    EXPECT_NEAR(ab.geometry.overlap, ba.geometry.overlap, 1e-13 * s);
    EXPECT_NEAR(ab.depth, ba.depth, 1e-13 * s);
    EXPECT_NEAR(ab.lambda, 1.0 - ba.lambda, 1e-11);
    EXPECT_LT((ab.geometry.branchA - ba.geometry.branchB).norm(), 1e-11 * s);
  }
}

// The solve against an independent maximisation (dense solves, scan + golden section + secant
// on S'), cold and warm, on random shapes up to aspect 10, deep overlaps and far-apart pairs:
// never NaN, always converged, F, lambda, the normal and the PW point agree. Prints the iteration
// statistics that docs/ellipsoids.md reports.
TEST(EllipsoidContact, NewtonSolveAgainstBruteForceColdAndWarm) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> logEps(-6.0, -0.5), far(1.0, 3.0), tiny(-1.0, 1.0);
  int coldTotal = 0, coldMax = 0, warmTotal = 0, warmMax = 0, warmOne = 0, n = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const double aspect = trial % 3 == 0 ? 10.0 : 3.0;
    Config c = randomConfig(rng, std::pow(10.0, logEps(rng)), aspect);
    if (trial % 5 == 0) c.r *= far(rng);  // apart
    const Sym3 xa = c.xa(), xb = c.xb();
    const pw::Solution cold = contactFunction(c.r, xa, xb, 0.0);
    const etest::ReferenceContact ref = etest::referenceContact(c.r, xa.dense(), xb.dense());
    ASSERT_TRUE(cold.converged);
    ASSERT_TRUE(std::isfinite(cold.contactFunction) && std::isfinite(cold.lambda) && cold.p.allFinite());
    EXPECT_NEAR(cold.contactFunction / ref.contactFunction, 1.0, 1e-12);
    EXPECT_NEAR(cold.lambda, ref.lambda, 1e-11);
    EXPECT_LT((cold.p.normalized() - ref.normal).norm(), 1e-11);
    coldTotal += cold.iterations;
    coldMax = std::max(coldMax, cold.iterations);
    // A DEM step later: B moved by 1e-5 of its size and turned by 1e-5 rad.
    Config next = c;
    next.r += 1e-5 * scaleOf(c) * randomUnitVector(rng);
    next.qb = rotation::rotationQuaternion(1e-5 * randomUnitVector(rng)) * c.qb;
    const pw::Solution warm = contactFunction(next.r, xa, next.xb(), cold.lambda);
    const etest::ReferenceContact ref2 = etest::referenceContact(next.r, xa.dense(), next.xb().dense());
    ASSERT_TRUE(warm.converged);
    EXPECT_NEAR(warm.contactFunction / ref2.contactFunction, 1.0, 1e-12);
    EXPECT_LT((warm.p.normalized() - ref2.normal).norm(), 1e-11);
    warmTotal += warm.iterations;
    warmMax = std::max(warmMax, warm.iterations);
    warmOne += warm.iterations == 1;
    ++n;
  }
  std::cout << "[ellipsoid PW solve] cold: mean " << double(coldTotal) / n << " max " << coldMax
            << " evaluations; warm (1e-5 step): mean " << double(warmTotal) / n << " max " << warmMax
            << ", one evaluation in " << 100.0 * warmOne / n << " %\n";
  EXPECT_LE(coldMax, 12);
  EXPECT_LE(warmMax, 4);
}

// The early-finished result (extrapolated from a Newton step below kStepTolerance) agrees with
// the fully converged one: normal, overlap and contact point to ~1e-13 of the size.
TEST(EllipsoidContact, WarmStartedResultEqualsConvergedResult) {
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> logEps(-5.0, -1.0), logStep(-7.0, -3.0);
  double worstN = 0, worstOverlap = 0, worstPoint = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Config c = randomConfig(rng, std::pow(10.0, logEps(rng)));
    const Sym3 xa = c.xa(), xb = c.xb();
    const etest::ReferenceContact ref = etest::referenceContact(c.r, xa.dense(), xb.dense());
    const double start = std::clamp(ref.lambda + std::pow(10.0, logStep(rng)), 1e-3, 1 - 1e-3);
    const EllipsoidContact w = ellipsoidEllipsoid(c.r, xa, xb, start, 0.0);
    ASSERT_TRUE(w.touching);
    const double s = scaleOf(c);
    const Vec3 nref = ref.normal;
    const double ha = std::sqrt(xa.quadratic(nref)), hb = std::sqrt(xb.quadratic(nref));
    const double depthRef = (ha + hb) * (1 - std::sqrt(ref.contactFunction));
    worstN = std::max(worstN, (w.geometry.normal - nref).norm());
    worstOverlap = std::max(worstOverlap, std::abs(w.depth - depthRef) / s);
    // The returned point lies on the PW force line: (C - C_PW) parallel to n.
    worstPoint = std::max(worstPoint, (w.geometry.branchA - ref.pointFromA).cross(nref).norm() / s);
  }
  std::cout << "[warm start vs converged] normal " << worstN << ", depth " << worstOverlap << ", point " << worstPoint << "\n";
  EXPECT_LT(worstN, 1e-12);
  EXPECT_LT(worstOverlap, 1e-14);
  EXPECT_LT(worstPoint, 1e-12);
}

// Two ellipsoids aligned along x, tip to tip: F = (d/(aA + aB))^2, geometric depth aA + aB - d,
// force-equivalent overlap (L/H)^2 times it with H = aA + aB, contact point midway through the
// overlap on the axis. Then sliding across (along y): parabolic, with the curvature of two
// circles of the tips' radii of curvature rho = b^2/a, 1/(rho_A + rho_B).
TEST(EllipsoidContact, AlignedTipToTipExactAndParabolicSliding) {
  const Vec3 sa(3.0, 1.5, 1.0), sb(2.0, 1.2, 0.7);
  const Sym3 xa = shapeMatrix(sa, Quat::Identity()), xb = shapeMatrix(sb, Quat::Identity());
  const double h = sa.x() + sb.x(), d = h - 1e-3, l = 2.0;
  const EllipsoidContact c = ellipsoidEllipsoid(Vec3(d, 0, 0), xa, xb, 0.0, l);
  ASSERT_TRUE(c.touching);
  EXPECT_NEAR(c.contactFunction, d * d / (h * h), 1e-15);
  EXPECT_NEAR(c.depth, h - d, 1e-14);
  EXPECT_NEAR(c.geometry.overlap, l * l / (h * h) * (h - d), 1e-14);
  EXPECT_NEAR(c.energyOverKn, 0.5 * l * l * std::pow((h - d) / h, 2), 1e-16);
  EXPECT_LT((c.geometry.branchA - Vec3(sa.x() - 0.5 * (h - d), 0, 0)).norm(), 1e-14);
  // Sliding across by s: depth(s) = depth(0) - s^2/(2 (rho_A + rho_B)) + O(s^4).
  const double rho = sa.y() * sa.y() / sa.x() + sb.y() * sb.y() / sb.x();
  const double ds = 4e-3;
  auto depthAt = [&](double s) { return ellipsoidEllipsoid(Vec3(d, s, 0), xa, xb, 0.0, l).depth; };
  const double d0 = depthAt(0.0), d1 = depthAt(ds), d2 = depthAt(2 * ds), dm = depthAt(-ds);
  EXPECT_NEAR(d1, dm, 1e-15);                  // no first-order change
  EXPECT_NEAR((d2 - d0) / (d1 - d0), 4.0, 1e-2);  // parabolic
  const double curvature = -2.0 * (d1 - d0) / (ds * ds);
  EXPECT_NEAR(curvature * rho, 1.0, 2e-2);
}

// Along the line of centres (R -> t R) lambda and the normal do not change and sqrt(F) is
// proportional to t, so overlap and depth are exactly linear in the approach. Along the normal,
// in general positions, they are linear to O(overlap/size) with slope -1 for the depth and
// -(L/H)^2 for the force-equivalent overlap. A rotation of B changes the depth linearly, with the
// slope the support function predicts: d h_B(n)/dtheta = e.(X_B n x n)/h_B. A sliding
// displacement across n changes it to second order only.
TEST(EllipsoidContact, OverlapLinearInApproachAndRotationParabolicInSliding) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const Config c = randomConfig(rng, 1e-3);
    const Sym3 xa = c.xa(), xb = c.xb();
    const double len = 0.5 * scaleOf(c);  // a pair-constant L
    const EllipsoidContact c0 = ellipsoidEllipsoid(c.r, xa, xb, 0.0, len);
    ASSERT_TRUE(c0.touching);
    const Vec3 n = c0.geometry.normal;
    const double delta = c0.depth;
    auto at = [&](const Vec3& r, const Sym3& xbMoved) { return ellipsoidEllipsoid(r, xa, xbMoved, 0.0, len); };
    // Along R: exactly linear.
    {
      const EllipsoidContact p = at(c.r * (1 + 1e-4), xb), m = at(c.r * (1 - 1e-4), xb);
      EXPECT_NEAR(p.geometry.overlap + m.geometry.overlap, 2 * c0.geometry.overlap, 1e-12 * delta);
      EXPECT_NEAR(p.depth + m.depth, 2 * c0.depth, 1e-12 * delta);
    }
    // Along n: slope -1 (depth), -(L/H)^2 (overlap), curvature negligible.
    {
      const double s = 0.5 * delta;
      const EllipsoidContact p = at(c.r + s * n, xb), m = at(c.r - s * n, xb);
      const double slope = (p.depth - m.depth) / (2 * s);
      EXPECT_NEAR(slope, -1.0, 1e-2);
      const double fslope = (p.geometry.overlap - m.geometry.overlap) / (2 * s);
      EXPECT_NEAR(fslope / (-(len * len) / (c0.supportSum * c0.supportSum)), 1.0, 1e-2);
      EXPECT_LT(std::abs(p.depth + m.depth - 2 * c0.depth), 1e-2 * std::abs(p.depth - m.depth));
    }
    // Rotation of B about the axis of the largest support-function change.
    {
      const Vec3 xbn = xb * n;
      const double hb = std::sqrt(n.dot(xbn));
      const Vec3 axis = xbn.cross(n);
      if (axis.norm() < 0.05 * hb) continue;  // n near a principal axis: no first-order change
      const Vec3 e = axis.normalized();
      const double expected = e.dot(xbn.cross(n)) / hb;
      const double th = 1e-4;  // small: the depth changes by ~1e-4 of the size
      auto rotated = [&](double a) { return shapeMatrix(c.axesB, rotation::rotationQuaternion(a * e) * c.qb); };
      const EllipsoidContact p = at(c.r, rotated(th)), m = at(c.r, rotated(-th));
      const double slope = (p.depth - m.depth) / (2 * th);
      EXPECT_NEAR(slope / expected, 1.0, 2e-2);
      EXPECT_LT(std::abs(p.depth + m.depth - 2 * c0.depth), 1e-2 * std::abs(p.depth - m.depth));
    }
    // Sliding across n: first-order change small against the normal slope of 1.
    {
      const Vec3 t = n.cross(randomUnitVector(rng)).normalized();
      const double s = 0.5 * delta;
      const EllipsoidContact p = at(c.r + s * t, xb), m = at(c.r - s * t, xb);
      EXPECT_LT(std::abs(p.depth - m.depth) / (2 * s), 2e-2);
    }
  }
}

namespace {

// Elastic energy of the normal spring (kn = 1) with the potential length held fixed, as a
// function of B's translation dx and rotation vector dth (applied on the left, world frame).
double pairEnergy(const Config& c, const Vec3& dxA, const Vec3& dthA, const Vec3& dxB, const Vec3& dthB,
                  double len) {
  const Sym3 xa = shapeMatrix(c.axesA, rotation::rotationQuaternion(dthA) * c.qa);
  const Sym3 xb = shapeMatrix(c.axesB, rotation::rotationQuaternion(dthB) * c.qb);
  return ellipsoidEllipsoid(c.r + dxB - dxA, xa, xb, 0.0, len).energyOverKn;
}

}  // namespace

// The force kn overlap n applied at the contact point is minus the gradient of the energy the
// kernel reports, forces and torques on both bodies (finite differences, HOOMD's check), for
// both potential-length policies. This is what makes a frictionless collision conserve energy.
TEST(EllipsoidContact, ForceAndTorquesAreMinusGradientOfEnergy) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> logEps(-3.0, -1.3);
  for (int trial = 0; trial < 100; ++trial) {
    const Config c = randomConfig(rng, std::pow(10.0, logEps(rng)));
    const EllipsoidContact c0 = ellipsoidEllipsoid(c.r, c.xa(), c.xb(), 0.0, 0.0);
    ASSERT_TRUE(c0.touching);
    for (double len : {c0.potentialLength, 0.5 * scaleOf(c)}) {
      const EllipsoidContact k = ellipsoidEllipsoid(c.r, c.xa(), c.xb(), 0.0, len);
      const Vec3 f = k.geometry.overlap * k.geometry.normal;  // on B (kn = 1)
      const Vec3 ta = k.geometry.branchA.cross(-f), tb = k.geometry.branchB.cross(f);
      const double h = 1e-6 * scaleOf(c), a = 1e-6;
      const double fscale = f.norm(), tscale = f.norm() * scaleOf(c);
      const Vec3 z = Vec3::Zero();
      for (int i = 0; i < 3; ++i) {
        const Vec3 e = Vec3::Unit(i);
        const double dUdxB = (pairEnergy(c, z, z, h * e, z, len) - pairEnergy(c, z, z, -h * e, z, len)) / (2 * h);
        const double dUdxA = (pairEnergy(c, h * e, z, z, z, len) - pairEnergy(c, -h * e, z, z, z, len)) / (2 * h);
        const double dUdtB = (pairEnergy(c, z, z, z, a * e, len) - pairEnergy(c, z, z, z, -a * e, len)) / (2 * a);
        const double dUdtA = (pairEnergy(c, z, a * e, z, z, len) - pairEnergy(c, z, -a * e, z, z, len)) / (2 * a);
        EXPECT_NEAR(-dUdxB, f[i], 1e-6 * fscale);
        EXPECT_NEAR(-dUdxA, -f[i], 1e-6 * fscale);
        EXPECT_NEAR(-dUdtB, tb[i], 1e-6 * tscale);
        EXPECT_NEAR(-dUdtA, ta[i], 1e-6 * tscale);
      }
    }
  }
}

// Work of the normal force on B around a closed loop of translations along the normal and
// rotations of B, which keeps the pair in contact: zero for the potential's force (to the
// spectral accuracy of the periodic trapezoidal rule), clearly not zero for a force proportional
// to the geometric depth along the same normal (Woo's ellipsoid law): that law creates or
// destroys energy in cycles.
TEST(EllipsoidContact, ClosedLoopWorkVanishesOnlyForThePotential) {
  std::mt19937_64 rng(9);
  double worstPotential = 0.0, smallestDepthLaw = 1e9;
  for (int trial = 0; trial < 20; ++trial) {
    const Config c = randomConfig(rng, 3e-3);
    const EllipsoidContact c0 = ellipsoidEllipsoid(c.r, c.xa(), c.xb(), 0.0, 0.0);
    ASSERT_TRUE(c0.touching);
    const Vec3 n = c0.geometry.normal;
    const Vec3 e = (c.xb() * n).cross(n).normalized();
    const double amp = 0.4 * c0.depth;                   // in and out along n
    const double rot = 0.4 * c0.depth / scaleOf(c) * 4;  // rotation amplitude [rad]
    const int steps = 512;
    double work[2] = {0, 0}, absWork[2] = {0, 0};
    for (int k = 0; k < steps; ++k) {
      const double t = 2 * kPi * k / steps;
      const Vec3 r = c.r - amp * std::sin(t) * n, drdt = -amp * std::cos(t) * n;
      const double th = rot * std::cos(t), dthdt = -rot * std::sin(t);
      const Sym3 xb = shapeMatrix(c.axesB, rotation::rotationQuaternion(th * e) * c.qb);
      const EllipsoidContact k0 = ellipsoidEllipsoid(r, c.xa(), xb, 0.0, c0.potentialLength);
      ASSERT_TRUE(k0.touching);
      for (int law = 0; law < 2; ++law) {
        const double overlap = law == 0 ? k0.geometry.overlap : k0.depth;
        const Vec3 f = overlap * k0.geometry.normal;
        const double power = f.dot(drdt) + k0.geometry.branchB.cross(f).dot(e) * dthdt;
        work[law] += power * 2 * kPi / steps;
        absWork[law] += std::abs(power) * 2 * kPi / steps;
      }
    }
    worstPotential = std::max(worstPotential, std::abs(work[0]) / absWork[0]);
    smallestDepthLaw = std::min(smallestDepthLaw, std::abs(work[1]) / absWork[1]);
  }
  std::cout << "[closed loop] |W|/int|P|: potential " << worstPotential << ", depth law (min) "
            << smallestDepthLaw << "\n";
  EXPECT_LT(worstPotential, 1e-9);
  EXPECT_GT(smallestDepthLaw, 1e-4);
}

// The plane kernel: exact overlap (against the deepest of points sampled on the surface) and its
// force kn overlap m at the contact point is minus the gradient of the energy.
TEST(EllipsoidPlane, ExactOverlapAndConservativeForce) {
  std::mt19937_64 rng(10);
  for (int trial = 0; trial < 50; ++trial) {
    const Vec3 axes = randomSemiAxes(rng, 1.0, 4.0);
    const Quat q = randomRotation(rng);
    const Vec3 m = randomUnitVector(rng), p = randomUnitVector(rng);
    const Vec3 x = p + m * (std::sqrt(shapeMatrix(axes, q).quadratic(m)) - 0.01);
    const EllipsoidPlaneContact c = ellipsoidPlane(x, shapeMatrix(axes, q), p, m);
    ASSERT_TRUE(c.touching);
    double deepest = 1e9;
    const int n = 300;
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j < 2 * n; ++j) {
        const double th = kPi * i / n, ph = kPi * j / n;
        const Vec3 y = x + q * Vec3(axes.x() * std::sin(th) * std::cos(ph), axes.y() * std::sin(th) * std::sin(ph),
                                    axes.z() * std::cos(th));
        deepest = std::min(deepest, (y - p).dot(m));
      }
    }
    EXPECT_NEAR(c.geometry.overlap, -deepest, 1e-4 * axes.x());
    EXPECT_GE(c.geometry.overlap, -deepest - 1e-14);
    const Vec3 f = c.geometry.overlap * m;
    const Vec3 t = c.geometry.branchB.cross(f);
    auto energy = [&](const Vec3& dx, const Vec3& dth) {
      return ellipsoidPlane(x + dx, shapeMatrix(axes, rotation::rotationQuaternion(dth) * q), p, m).energyOverKn;
    };
    const double h = 1e-7, z = 0;
    for (int i = 0; i < 3; ++i) {
      const Vec3 e = Vec3::Unit(i);
      EXPECT_NEAR(-(energy(h * e, Vec3::Zero()) - energy(-h * e, Vec3::Zero())) / (2 * h), f[i], 1e-7 + z);
      EXPECT_NEAR(-(energy(Vec3::Zero(), h * e) - energy(Vec3::Zero(), -h * e)) / (2 * h), t[i], 1e-7);
    }
  }
}

// No missed contacts: on random dense sets (elongated grains at 60 % of their bounding-sphere
// packing), every pair that brute force finds touching (full solve, F < 1) passes both filters
// and is found by the kernel; the kernel finds no other. Prints how much the filters prune.
TEST(EllipsoidContact, NoMissedContactsAgainstBruteForce) {
  std::mt19937_64 rng(12);
  int touching = 0, boundingPass = 0, axisPass = 0, pairs = 0;
  for (int set = 0; set < 4; ++set) {
    const int n = 250;
    const double box = 9.0;
    std::uniform_real_distribution<double> pos(0.0, box);
    std::vector<Vec3> x(n), axes(n);
    std::vector<Sym3> shape(n);
    for (int i = 0; i < n; ++i) {
      x[i] = Vec3(pos(rng), pos(rng), pos(rng));
      axes[i] = randomSemiAxes(rng, 0.6, 3.0);
      shape[i] = shapeMatrix(axes[i], randomRotation(rng));
    }
    for (int i = 0; i < n; ++i) {
      for (int j = i + 1; j < n; ++j) {
        const Vec3 r = x[j] - x[i];
        ++pairs;
        const bool truth = contactFunction(r, shape[i], shape[j]).contactFunction < 1.0;
        const bool bounding = boundingSpheresOverlap(r, boundingRadius(axes[i]), boundingRadius(axes[j]));
        const bool axis = !separatedAlongCentreLine(r, shape[i], shape[j]);
        touching += truth;
        boundingPass += bounding;
        axisPass += bounding && axis;
        if (truth) {
          EXPECT_TRUE(bounding);
          EXPECT_TRUE(axis);
        }
        if (bounding && axis) {
          EXPECT_EQ(ellipsoidEllipsoid(r, shape[i], shape[j], 0.0, 0.0).touching, truth);
        }
      }
    }
  }
  std::cout << "[filters] pairs " << pairs << ", touching " << touching << ", pass bounding spheres "
            << boundingPass << ", pass both " << axisPass << "\n";
  EXPECT_GT(touching, 100);
  EXPECT_LT(axisPass, boundingPass);
}

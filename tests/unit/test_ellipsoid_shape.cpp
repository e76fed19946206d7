// Ellipsoid shape functions against independent numbers: [O]'s parameters, mass and inertia by
// slicing quadrature, support distances and bounding boxes by sampling the surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "geometry/ellipsoid_shape.hpp"
#include "geometry/ellipsoid_time_step.hpp"
#include "test_ellipsoid_helpers.hpp"

using namespace grainlab;
using namespace grainlab::geometry;

TEST(EllipsoidShape, OuadfelParametersRoundTrip) {
  for (double elr : {1.0, 0.8, 0.7, 0.5}) {
    for (double flr : {1.0, 0.9, 0.6}) {
      const Vec3 s = semiAxesFromOuadfel(10.0, elr, flr);
      EXPECT_NEAR(equivalentRadius(s), 10.0, 1e-12);
      EXPECT_NEAR(elongationRatio(s), elr, 1e-14);
      EXPECT_NEAR(flatnessRatio(s), flr, 1e-14);
      EXPECT_FALSE(semiAxesProblem(s).has_value());
    }
  }
  // [O]'s eccentricities: 0.176 for elr = 0.7 and 0.111 for elr = 0.8.
  EXPECT_NEAR(eccentricity(semiAxesFromOuadfel(1.0, 0.7, 1.0)), 0.176, 5e-4);
  EXPECT_NEAR(eccentricity(semiAxesFromOuadfel(1.0, 0.8, 1.0)), 0.111, 5e-4);
  EXPECT_TRUE(semiAxesProblem(Vec3(1.0, 2.0, 0.5)).has_value());
  EXPECT_TRUE(semiAxesProblem(Vec3(1.0, 0.5, 0.0)).has_value());
  EXPECT_TRUE(semiAxesProblem(Vec3(1.0, NAN, 0.5)).has_value());
}

// Mass and principal moments by slicing along each axis: a slice at x is an ellipse of semi-axes
// p = b s, q = c s (s = sqrt(1 - x^2/a^2)) with area pi p q and second moments pi p^3 q/4,
// pi p q^3/4. Simpson's rule over x, then compared with the closed forms (m/5 (b^2 + c^2), ...;
// [O] eq. 3.19's 2/5 would be off by a factor of two).
TEST(EllipsoidShape, MassAndInertiaBySlicing) {
  const Vec3 s(3.0, 2.0, 1.2);
  const double rho = 2600.0;
  // Integrate along axis k with the two other semi-axes (u, w): mass, and the moments about k
  // (slice's polar moment) and about the other two axes (slice moment + x^2 dm).
  auto slice = [&](int k, int i, int j) {
    const double a = s[k], b = s[i], c = s[j];
    const int n = 20000;  // even
    double mass = 0, ik = 0, ii = 0, ij = 0;
    for (int t = 0; t <= n; ++t) {
      const double x = -a + 2.0 * a * t / n;
      const double sc2 = std::max(0.0, 1.0 - x * x / (a * a));
      const double sc = std::sqrt(sc2);
      const double p = b * sc, q = c * sc;
      const double wgt = (t == 0 || t == n) ? 1.0 : (t % 2 ? 4.0 : 2.0);
      const double area = kPi * p * q;
      const double myy = kPi * p * p * p * q / 4.0;  // int y^2 dA (y along i)
      const double mzz = kPi * p * q * q * q / 4.0;  // int z^2 dA (z along j)
      mass += wgt * area;
      ik += wgt * (myy + mzz);
      ii += wgt * (mzz + x * x * area);
      ij += wgt * (myy + x * x * area);
    }
    const double h = 2.0 * a / n / 3.0 * rho;
    return std::array<double, 4>{mass * h, ik * h, ii * h, ij * h};
  };
  const double m = ellipsoidMass(s, rho);
  const Vec3 inertia = ellipsoidPrincipalInertia(s, m);
  const auto ax = slice(0, 1, 2), ay = slice(1, 0, 2);
  // sqrt(1 - x^2) at the ends limits Simpson to ~n^-1.5: 1e-6 is ample.
  EXPECT_NEAR(ax[0] / m, 1.0, 1e-6);
  EXPECT_NEAR(ax[1] / inertia.x(), 1.0, 1e-6);
  EXPECT_NEAR(ax[2] / inertia.y(), 1.0, 1e-6);
  EXPECT_NEAR(ax[3] / inertia.z(), 1.0, 1e-6);
  EXPECT_NEAR(ay[1] / inertia.y(), 1.0, 1e-6);
  // Sphere limit: 2/5 m r^2.
  const Vec3 ball = ellipsoidPrincipalInertia(Vec3::Constant(2.0), 3.0);
  EXPECT_NEAR(ball.x(), 0.4 * 3.0 * 4.0, 1e-14);
}

// The shape matrix gives the support distance sqrt(u^T X u) = max over the surface of u.y, and
// the axis-aligned half extents; both checked against points sampled on the rotated surface.
TEST(EllipsoidShape, ShapeMatrixSupportAndBoundingBox) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 s = etest::randomSemiAxes(rng, 1.0, 3.0);
    const Quat q = etest::randomRotation(rng);
    const Sym3 x = shapeMatrix(s, q);
    const Mat3 dense = q.toRotationMatrix() * s.cwiseProduct(s).asDiagonal() * q.toRotationMatrix().transpose();
    EXPECT_LT((x.dense() - dense).norm(), 1e-13 * s.squaredNorm());
    const Vec3 u = etest::randomUnitVector(rng);
    double best = -1e9;
    Vec3 extent = Vec3::Zero();
    const int n = 400;
    for (int i = 0; i <= n; ++i) {
      const double th = kPi * i / n;
      for (int j = 0; j < 2 * n; ++j) {
        const double ph = kPi * j / n;
        const Vec3 y = q * Vec3(s.x() * std::sin(th) * std::cos(ph), s.y() * std::sin(th) * std::sin(ph),
                                s.z() * std::cos(th));
        best = std::max(best, u.dot(y));
        extent = extent.cwiseMax(y.cwiseAbs());
      }
    }
    const double h = std::sqrt(x.quadratic(u));
    EXPECT_LE(best, h * (1 + 1e-12));
    EXPECT_GT(best, h * (1 - 1e-4));
    const Vec3 box = axisAlignedHalfExtents(x);
    EXPECT_LT(((extent - box).array() / box.array()).abs().maxCoeff(), 1e-4);
    EXPECT_TRUE((extent.array() <= box.array() * (1 + 1e-12)).all());
    EXPECT_LE(box.maxCoeff(), boundingRadius(s) * (1 + 1e-14));
  }
}

// The torque of a unit normal force about each body axis never exceeds maxNormalForceArms
// (b - c, a - c, a - b) and reaches it; a tangential force's arm (distance of the point from the
// axis) never exceeds maxTangentialForceArms (b, a, a). Sampled over the surface.
TEST(EllipsoidShape, ContactForceArmsAboutTheBodyAxes) {
  const Vec3 s(3.0, 2.0, 1.0);
  Vec3 worstNormal = Vec3::Zero(), worstReach = Vec3::Zero();
  const int n = 600;
  for (int i = 0; i <= n; ++i) {
    const double th = kPi * i / n;
    for (int j = 0; j < 2 * n; ++j) {
      const double ph = kPi * j / n;
      const Vec3 y(s.x() * std::sin(th) * std::cos(ph), s.y() * std::sin(th) * std::sin(ph), s.z() * std::cos(th));
      const Vec3 normal = y.cwiseQuotient(s.cwiseProduct(s)).normalized();
      worstNormal = worstNormal.cwiseMax(y.cross(normal).cwiseAbs());
      for (int k = 0; k < 3; ++k) worstReach[k] = std::max(worstReach[k], (y - y[k] * Vec3::Unit(k)).norm());
    }
  }
  const Vec3 arms = maxNormalForceArms(s), reach = maxTangentialForceArms(s);
  for (int k = 0; k < 3; ++k) {
    EXPECT_LE(worstNormal[k], arms[k] * (1 + 1e-12));
    EXPECT_GT(worstNormal[k], arms[k] * (1 - 1e-4));
    EXPECT_LE(worstReach[k], reach[k] * (1 + 1e-12));
    EXPECT_GT(worstReach[k], reach[k] * (1 - 1e-4));
  }
}

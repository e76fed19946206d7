// Overlap depth against an exact 2D solution ([O]'s check, docs/physics.md §3): ellipsoids with one
// principal axis along z and their centres in the plane z = 0 meet in that symmetry plane, where
// their sections are ellipses. The exact depth of two overlapping ellipses is their penetration
// depth, the shortest translation that separates them: min over unit u of h_A(u) + h_B(u) - u.R
// (the distance from R to the boundary of the Minkowski sum, whose support function is
// h_A + h_B), computed here by a dense scan of the angle and golden-section refinement of every
// local minimum, from the ellipses' own semi-axes and angles (no Perram–Wertheim code).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include "geometry/ellipsoid_contacts.hpp"
#include "test_ellipsoid_helpers.hpp"

using namespace grainlab;
using namespace grainlab::geometry;

namespace {

struct Ellipse {
  double p, q, angle;  // semi-axes along the rotated x and y, rotation about z
  double support(double theta) const {
    const double c = std::cos(theta - angle), s = std::sin(theta - angle);
    return std::sqrt(p * p * c * c + q * q * s * s);
  }
};

struct Depth2d {
  double depth;  // > 0 overlapping (penetration depth), < 0 apart (minus the distance)
  double angle;  // direction of the separating translation of B
};

// g(theta) = h_A + h_B - u.R. Overlapping: depth = min g. Apart: distance = max over u of
// (u.R - h_A - h_B) = -min g too, so min g is the signed depth in both cases.
Depth2d exactDepth(const Ellipse& a, const Ellipse& b, double rx, double ry) {
  auto g = [&](double t) { return a.support(t) + b.support(t) - std::cos(t) * rx - std::sin(t) * ry; };
  const int n = 3600;
  std::vector<double> v(n);
  for (int i = 0; i < n; ++i) v[i] = g(2 * kPi * i / n);
  Depth2d best{1e300, 0.0};
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int i = 0; i < n; ++i) {
    if (v[i] > v[(i + n - 1) % n] || v[i] > v[(i + 1) % n]) continue;  // not a local minimum
    double lo = 2 * kPi * (i - 1) / n, hi = 2 * kPi * (i + 1) / n;
    double x1 = hi - phi * (hi - lo), x2 = lo + phi * (hi - lo), f1 = g(x1), f2 = g(x2);
    while (hi - lo > 1e-12) {
      if (f1 < f2) {
        hi = x2; x2 = x1; f2 = f1; x1 = hi - phi * (hi - lo); f1 = g(x1);
      } else {
        lo = x1; x1 = x2; f1 = f2; x2 = lo + phi * (hi - lo); f2 = g(x2);
      }
    }
    const double t = 0.5 * (lo + hi);
    if (g(t) < best.depth) best = {g(t), t};
  }
  return best;
}

// The 3D ellipsoid whose principal axis `normalAxis` lies along z and whose other two axes are
// turned by `angle` about z, and its section by z = 0.
struct Cut {
  Vec3 axes;
  Quat q;
  Ellipse section;
};
Cut makeCut(const Vec3& axes, int normalAxis, double angle) {
  // Body axis normalAxis -> world z; the remaining two (in order) -> world x, y before the turn.
  Quat base = Quat::Identity();
  if (normalAxis == 0) base = Quat(Eigen::AngleAxisd(-0.5 * kPi, Vec3::UnitY()));  // x->z, z->-x
  if (normalAxis == 1) base = Quat(Eigen::AngleAxisd(0.5 * kPi, Vec3::UnitX()));   // y->z, z->-y
  const Quat q = Quat(Eigen::AngleAxisd(angle, Vec3::UnitZ())) * base;
  Ellipse e{0, 0, angle};
  if (normalAxis == 0) e = {axes.z(), axes.y(), angle};
  if (normalAxis == 1) e = {axes.x(), axes.z(), angle};
  if (normalAxis == 2) e = {axes.x(), axes.y(), angle};
  return {axes, q, e};
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5))];
}

}  // namespace

// 2000 random overlapping pairs (aspect up to 3, relative approach 1e-4..1e-1 past touching):
// the kernel's geometric depth against the exact penetration depth. Its error is second order
// in the overlap (the PW normal and the separating direction agree at touching), so the test
// bounds |depth - exact| by a multiple of exact^2 / c_min and prints the error distribution by
// overlap class (docs/ellipsoids.md), and that of the force-equivalent overlap with the
// pair-constant L = rA + rB (a stiffness factor (L/H)^2, not an error of the geometry). With the
// length frozen at birth the force overlap equals the depth when the pair approached along R
// (lambda and n do not change along R).
TEST(EllipsoidDepth2d, GeometricDepthAgainstExactEllipsePenetration) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> angle(0.0, 2 * kPi), logEps(-4.0, -1.0);
  std::uniform_int_distribution<int> axis(0, 2);
  struct Sample {
    double relDepth, relErr, relErrConst, normalErr;
  };
  std::vector<Sample> samples;
  double worstScaled = 0.0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Cut a = makeCut(etest::randomSemiAxes(rng, 1.0, 3.0), axis(rng), angle(rng));
    const Cut b = makeCut(etest::randomSemiAxes(rng, 1.0, 3.0), axis(rng), angle(rng));
    const double dir = angle(rng), ux = std::cos(dir), uy = std::sin(dir);
    // Touching distance along u from F's homogeneity (this only places the pair; the depth it is
    // compared with is computed independently below).
    const Sym3 xa = shapeMatrix(a.axes, a.q), xb = shapeMatrix(b.axes, b.q);
    const Vec3 u(ux, uy, 0.0);
    const double dTouch = 1.0 / std::sqrt(contactFunction(u, xa, xb).contactFunction);
    const double d = dTouch * (1.0 - std::pow(10.0, logEps(rng)));
    const Depth2d exact = exactDepth(a.section, b.section, d * ux, d * uy);
    ASSERT_GT(exact.depth, 0.0);
    const Vec3 r = d * u;
    const EllipsoidContact c = ellipsoidEllipsoid(r, xa, xb, 0.0, 0.0);
    const double constL = equivalentRadius(a.axes) + equivalentRadius(b.axes);
    const EllipsoidContact cConst = ellipsoidEllipsoid(r, xa, xb, 0.0, constL);
    ASSERT_TRUE(c.touching);
    EXPECT_NEAR(c.geometry.normal.z(), 0.0, 1e-12);  // the symmetry plane holds the normal
    const double cMin = std::min(a.axes.z(), b.axes.z());
    const double err = c.depth - exact.depth;
    EXPECT_GE(err, -1e-12 * cMin);  // the PD is the minimum over directions: never above depth
    worstScaled = std::max(worstScaled, err / (exact.depth * exact.depth / cMin));
    const double nerr = std::acos(std::clamp(c.geometry.normal.x() * std::cos(exact.angle) +
                                                 c.geometry.normal.y() * std::sin(exact.angle), -1.0, 1.0));
    samples.push_back({exact.depth / cMin, err / exact.depth, (cConst.geometry.overlap - exact.depth) / exact.depth, nerr});
  }
  std::cout << "[2D depth] " << samples.size() << " configurations; error / (exact^2/c_min) at most "
            << worstScaled << "\n";
  std::cout << "  class (exact/c_min)   n    depth rel.err p50 / p90 / max      normal err p50 / max [rad]"
               "    L=rA+rB overlap rel.err p5 / p95\n";
  const double edges[] = {0.0, 1e-3, 1e-2, 1e-1, 1.0};
  for (int k = 0; k < 4; ++k) {
    std::vector<double> e, ne, ec;
    for (const Sample& s : samples) {
      if (s.relDepth < edges[k] || s.relDepth >= edges[k + 1]) continue;
      e.push_back(std::abs(s.relErr));
      ne.push_back(s.normalErr);
      ec.push_back(s.relErrConst);
    }
    std::cout << "  [" << edges[k] << ", " << edges[k + 1] << ")  " << e.size() << "   " << percentile(e, 0.5)
              << " / " << percentile(e, 0.9) << " / " << percentile(e, 1.0) << "    " << percentile(ne, 0.5) << " / "
              << percentile(ne, 1.0) << "    " << percentile(ec, 0.05) << " / " << percentile(ec, 0.95) << "\n";
  }
  EXPECT_LT(worstScaled, 0.25);
}

// Detection: for random pairs between 10 % overlap and 10 % apart, F < 1 exactly when the exact
// signed depth is positive.
TEST(EllipsoidDepth2d, ContactDetectionAgreesWithExactSign) {
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> angle(0.0, 2 * kPi), scale(0.9, 1.1);
  std::uniform_int_distribution<int> axis(0, 2);
  int touching = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const Cut a = makeCut(etest::randomSemiAxes(rng, 1.0, 3.0), axis(rng), angle(rng));
    const Cut b = makeCut(etest::randomSemiAxes(rng, 1.0, 3.0), axis(rng), angle(rng));
    const double dir = angle(rng);
    const Sym3 xa = shapeMatrix(a.axes, a.q), xb = shapeMatrix(b.axes, b.q);
    const Vec3 u(std::cos(dir), std::sin(dir), 0.0);
    const double dTouch = 1.0 / std::sqrt(contactFunction(u, xa, xb).contactFunction);
    const Vec3 r = u * dTouch * scale(rng);
    const Depth2d exact = exactDepth(a.section, b.section, r.x(), r.y());
    if (std::abs(exact.depth) < 1e-9) continue;  // at touching within the reference's accuracy
    const bool kernel = ellipsoidEllipsoid(r, xa, xb, 0.0, 0.0).touching;
    EXPECT_EQ(kernel, exact.depth > 0.0) << "exact " << exact.depth;
    touching += kernel;
  }
  EXPECT_GT(touching, 300);
  EXPECT_LT(touching, 700);
}

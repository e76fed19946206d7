#pragma once
// Shared pieces of the ellipsoid tests: random shapes and orientations, an independent brute-force
// evaluation of the Perram–Wertheim function, and a rigid body with the force of one contact.
#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "core/rigid_rotation.hpp"
#include "geometry/ellipsoid_contacts.hpp"
#include "geometry/ellipsoid_shape.hpp"

namespace grainlab::etest {

// Uniform random rotation (Shoemake's method).
inline Quat randomRotation(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double u1 = u(rng), u2 = 2.0 * kPi * u(rng), u3 = 2.0 * kPi * u(rng);
  const double s1 = std::sqrt(1.0 - u1), s2 = std::sqrt(u1);
  return Quat(s2 * std::cos(u3), s1 * std::sin(u2), s1 * std::cos(u2), s2 * std::sin(u3));
}

inline Vec3 randomUnitVector(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

// Semi-axes a >= b >= c with aspect ratios a/c up to maxAspect, equivalent radius about `size`.
inline Vec3 randomSemiAxes(std::mt19937_64& rng, double size, double maxAspect) {
  std::uniform_real_distribution<double> u(1.0, maxAspect);
  Vec3 s(size * u(rng), size * u(rng), size * u(rng));
  std::sort(s.data(), s.data() + 3, std::greater<double>());
  return s;
}

// S(lambda) with a dense inverse (Eigen's LU), independent of the kernel's adjugate pencil.
inline double denseS(const Vec3& r, const Mat3& xa, const Mat3& xb, double lambda) {
  const Mat3 g = (1.0 - lambda) * xa + lambda * xb;
  return lambda * (1.0 - lambda) * r.dot(g.lu().solve(r));
}

// max S by a scan of 400 points then golden-section search around the best one (S is concave,
// but the scan does not rely on it): slow and sure.
struct BruteForceMaximum {
  double lambda, value;
};
inline BruteForceMaximum bruteForceContactFunction(const Vec3& r, const Mat3& xa, const Mat3& xb) {
  int best = 1;
  double bestValue = -1.0;
  const int n = 400;
  for (int i = 1; i < n; ++i) {
    const double v = denseS(r, xa, xb, double(i) / n);
    if (v > bestValue) {
      bestValue = v;
      best = i;
    }
  }
  double lo = double(best - 1) / n, hi = double(best + 1) / n;
  const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - phi * (hi - lo), x2 = lo + phi * (hi - lo);
  double f1 = denseS(r, xa, xb, x1), f2 = denseS(r, xa, xb, x2);
  for (int it = 0; it < 200 && hi - lo > 1e-15; ++it) {
    if (f1 > f2) {
      hi = x2; x2 = x1; f2 = f1; x1 = hi - phi * (hi - lo); f1 = denseS(r, xa, xb, x1);
    } else {
      lo = x1; x1 = x2; f1 = f2; x2 = lo + phi * (hi - lo); f2 = denseS(r, xa, xb, x2);
    }
  }
  const double l = 0.5 * (lo + hi);
  return {l, denseS(r, xa, xb, l)};
}

// The maximiser to full precision, independently of the kernel: brute force, then secant steps
// on S'(lambda) evaluated with dense solves. Returns lambda, F, the unit normal and the
// Perram–Wertheim point relative to x_A.
struct ReferenceContact {
  double lambda, contactFunction;
  Vec3 normal, pointFromA;
};
inline ReferenceContact referenceContact(const Vec3& r, const Mat3& xa, const Mat3& xb) {
  auto slope = [&](double l) {
    const Mat3 g = (1.0 - l) * xa + l * xb;
    const Vec3 p = g.lu().solve(r);
    return (1.0 - 2.0 * l) * r.dot(p) - l * (1.0 - l) * p.dot((xb - xa) * p);
  };
  const BruteForceMaximum bf = bruteForceContactFunction(r, xa, xb);
  double l0 = bf.lambda - 1e-6, l1 = bf.lambda + 1e-6;
  double s0 = slope(l0), s1 = slope(l1);
  for (int it = 0; it < 60 && s1 != s0 && std::abs(l1 - l0) > 1e-17; ++it) {
    const double l2 = l1 - s1 * (l1 - l0) / (s1 - s0);
    l0 = l1;
    s0 = s1;
    l1 = l2;
    s1 = slope(l1);
  }
  const Mat3 g = (1.0 - l1) * xa + l1 * xb;
  const Vec3 p = g.lu().solve(r);
  return {l1, l1 * (1.0 - l1) * r.dot(p), p.normalized(), (1.0 - l1) * (xa * p)};
}

// A rigid ellipsoid in the engine's leapfrog state: position and orientation at full steps,
// velocity and world angular velocity at mid-steps.
struct Body {
  Vec3 x = Vec3::Zero(), v = Vec3::Zero();
  Quat q = Quat::Identity();
  Vec3 w = Vec3::Zero();
  Vec3 axes = Vec3::Ones();
  double m = 1.0;
  Vec3 inertia = Vec3::Ones();

  static Body ellipsoid(const Vec3& axes, double density) {
    Body b;
    b.axes = axes;
    b.m = geometry::ellipsoidMass(axes, density);
    b.inertia = geometry::ellipsoidPrincipalInertia(axes, b.m);
    return b;
  }
  geometry::Sym3 shape() const { return geometry::shapeMatrix(axes, q); }
  // Angular momentum at the current mid-step (the step that led to x, q had length dt).
  Vec3 angularMomentum(double dt) const { return rotation::midStepAngularMomentum(q, w, inertia, dt); }
  double kineticEnergy(double dt) const {
    return 0.5 * m * v.squaredNorm() + rotation::rotationalKineticEnergy(angularMomentum(dt), w);
  }
  // Leapfrog step under force f and torque t (world), undamped or damped.
  void advance(const Vec3& f, const Vec3& t, double dt, rotation::Damping damping = rotation::Damping::None,
               double alpha = 0.0) {
    if (damping == rotation::Damping::Viscous) {
      v = rotation::viscousMidpointKick(m * v, f, alpha, dt).momentum / m;
    } else {
      Vec3 fd = Vec3::Zero();
      if (damping == rotation::Damping::Local) fd = rotation::localDamping(f, v, alpha);
      v += (f + fd) * (dt / m);
    }
    const rotation::LeapfrogRotation r = rotation::leapfrogRotation(q, w, inertia, t, dt, dt, damping, alpha);
    q = r.step.orientation;
    w = r.step.angularVelocity;
    x += v * dt;
  }
};

// History of one ellipsoid pair as the engine would keep it.
struct PairHistory {
  double lambda = 0.0;
  double length = 0.0;  // frozen potential length (0: take H when the contact forms)
};

// How the test applies the normal force: the potential's force-equivalent overlap (the kernel's
// law), or the geometric depth h_A + h_B - n.R along the PW normal as Woo's Cg2_Ellipsoid_
// Ellipsoid_L6Geom does: the deliberately non-conservative control.
enum class NormalLaw { Potential, GeometricDepth };

struct PairForce {
  Vec3 onB = Vec3::Zero();
  Vec3 torqueA = Vec3::Zero(), torqueB = Vec3::Zero();
  double energy = 0.0;  // normal spring energy
  bool touching = false;
};

// Frictionless normal force of A on B. fixedLength > 0: pair-constant potential length;
// otherwise frozen at the first touching step (kept in `h`).
inline PairForce normalContactForce(const Body& a, const Body& b, double kn, PairHistory& h,
                                    double fixedLength = 0.0, NormalLaw law = NormalLaw::Potential) {
  const geometry::EllipsoidContact c = geometry::ellipsoidEllipsoid(
      b.x - a.x, a.shape(), b.shape(), h.lambda, fixedLength > 0.0 ? fixedLength : h.length);
  h.lambda = c.lambda;
  PairForce out;
  if (!c.touching) {
    h.length = 0.0;
    return out;
  }
  if (fixedLength <= 0.0) h.length = c.potentialLength;
  const double overlap = law == NormalLaw::Potential ? c.geometry.overlap : c.depth;
  out.touching = true;
  out.onB = kn * overlap * c.geometry.normal;
  out.torqueA = c.geometry.branchA.cross(-out.onB);
  out.torqueB = c.geometry.branchB.cross(out.onB);
  out.energy = kn * c.energyOverKn;
  return out;
}

}  // namespace grainlab::etest

// Ellipsoid kernels and the rotation integrator together, in small loops written in the test: an
// oblique frictionless collision (energy, momentum, angular momentum), an ellipsoid coming to
// rest on a plane under gravity (static overlap m g/kn), and the critical time step against the
// eigenfrequencies of a contact's stiffness.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <iostream>
#include <random>

#include "geometry/ellipsoid_contacts.hpp"
#include "geometry/ellipsoid_time_step.hpp"
#include "test_ellipsoid_helpers.hpp"

using namespace grainlab;
using namespace grainlab::geometry;
using etest::Body;

namespace {

struct CollisionResult {
  double energyError;     // |E_after - E_before| / E_before
  double maxEnergyDrift;  // largest |E(t) - E_before| / E_before during the contact
  double momentumError, angularMomentumError;
  double spinChange;  // |L_B after - L_B before| / |L_B before|: the torques mattered
  int contactSteps;
};

Vec3 totalAngularMomentum(const Body& a, const Body& b, double dt) {
  return a.m * a.x.cross(a.v) + b.m * b.x.cross(b.v) + a.angularMomentum(dt) + b.angularMomentum(dt);
}

// Two ellipsoids meet obliquely, spinning, with an offset of the line of approach; the test's own
// leapfrog moves them under the normal force of the kernel (kn) until they are apart again.
CollisionResult collide(double kn, double dt, double fixedLength, etest::NormalLaw law) {
  Body a = Body::ellipsoid(Vec3(1.0, 0.6, 0.4), 1.0);
  Body b = Body::ellipsoid(Vec3(0.8, 0.5, 0.45), 1.0);
  a.q = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 0.5).normalized()));
  b.q = Quat(Eigen::AngleAxisd(-1.1, Vec3(0.3, -1, 2).normalized()));
  const Vec3 u = Vec3(1.0, 0.3, 0.2).normalized(), side = u.cross(Vec3::UnitZ()).normalized();
  const double touch = 1.0 / std::sqrt(contactFunction(u, a.shape(), b.shape()).contactFunction);
  b.x = u * (touch + 2e-3);
  b.v = -0.1 * u + 0.03 * side;
  a.w = rotation::startingMidStepOmega(a.q, Vec3(0.5, -0.3, 0.2), a.inertia, dt);
  b.w = rotation::startingMidStepOmega(b.q, Vec3(-0.2, 0.4, 0.6), b.inertia, dt);
  const double e0 = a.kineticEnergy(dt) + b.kineticEnergy(dt);
  const Vec3 p0 = a.m * a.v + b.m * b.v;
  const Vec3 j0 = totalAngularMomentum(a, b, dt);
  const Vec3 lb0 = b.angularMomentum(dt);
  etest::PairHistory history;
  CollisionResult out{0, 0, 0, 0, 0, 0};
  bool started = false;
  for (int step = 0; step < 200000; ++step) {
    const etest::PairForce f = etest::normalContactForce(a, b, kn, history, fixedLength, law);
    if (f.touching) {
      started = true;
      ++out.contactSteps;
      // Energy at the full step n: velocities and angular momenta averaged over the half steps
      // around it, rotational energy L^n.I_world(q^n)^-1 L^n/2.
      const Vec3 vaOld = a.v, vbOld = b.v, laOld = a.angularMomentum(dt), lbOld = b.angularMomentum(dt);
      const Quat qa = a.q, qb = b.q;
      a.advance(-f.onB, f.torqueA, dt);
      b.advance(f.onB, f.torqueB, dt);
      const Vec3 la = 0.5 * (laOld + a.angularMomentum(dt)), lb = 0.5 * (lbOld + b.angularMomentum(dt));
      const double kin = 0.5 * a.m * (0.5 * (vaOld + a.v)).squaredNorm() + 0.5 * b.m * (0.5 * (vbOld + b.v)).squaredNorm() +
                         0.5 * la.dot(rotation::worldInertiaSolve(qa, a.inertia, la)) +
                         0.5 * lb.dot(rotation::worldInertiaSolve(qb, b.inertia, lb));
      out.maxEnergyDrift = std::max(out.maxEnergyDrift, std::abs(kin + f.energy - e0) / e0);
    } else {
      if (started) break;
      a.advance(Vec3::Zero(), Vec3::Zero(), dt);
      b.advance(Vec3::Zero(), Vec3::Zero(), dt);
    }
  }
  EXPECT_TRUE(started);
  out.energyError = std::abs(a.kineticEnergy(dt) + b.kineticEnergy(dt) - e0) / e0;
  out.momentumError = (a.m * a.v + b.m * b.v - p0).norm() / p0.norm();
  out.angularMomentumError = (totalAngularMomentum(a, b, dt) - j0).norm() / (b.m * b.v.norm() * touch);
  out.spinChange = (b.angularMomentum(dt) - lb0).norm() / lb0.norm();
  return out;
}

}  // namespace

// Frictionless, undamped: the normal force of the potential conserves the total energy (after
// vs before, to 1e-6 with ~3000 steps per contact), linear momentum exactly and angular momentum
// about the origin to round-off, for both potential-length policies. The contact torques change
// the spins by tens of per cent, so they are part of what is checked. The geometric-depth law
// (Woo's) on the same collision is the control that must fail.
TEST(EllipsoidCollision, FrictionlessObliqueCollisionConservesEnergyAndMomenta) {
  const double kn = 1e5, dt = 2e-6;
  for (double fixedLength : {0.0, 1.2}) {
    const CollisionResult r = collide(kn, dt, fixedLength, etest::NormalLaw::Potential);
    std::cout << "[collision L=" << (fixedLength > 0 ? "1.2" : "frozen") << "] steps in contact " << r.contactSteps
              << ", energy error " << r.energyError << " (max during contact " << r.maxEnergyDrift
              << "), momentum " << r.momentumError << ", angular momentum " << r.angularMomentumError
              << ", spin change of B " << r.spinChange << "\n";
    EXPECT_GT(r.contactSteps, 2000);
    EXPECT_LT(r.energyError, 1e-6);
    EXPECT_LT(r.momentumError, 1e-13);
    EXPECT_LT(r.angularMomentumError, 1e-11);
    EXPECT_GT(r.spinChange, 0.1);
  }
  const CollisionResult wrong = collide(kn, dt, 0.0, etest::NormalLaw::GeometricDepth);
  std::cout << "[collision, geometric-depth law] energy error " << wrong.energyError << "\n";
  EXPECT_GT(wrong.energyError, 1e-6);  // the criterion above catches it
}

// The energy error of the potential's collision is the integrator's, O(dt^2): the least-squares
// slope of log(max energy error during contact) on log(dt) over a 16x range of dt is 2 (the
// individual maxima scatter with the phase of the contact's onset within a step).
TEST(EllipsoidCollision, EnergyErrorDuringContactIsSecondOrder) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (double dt : {3.2e-5, 1.6e-5, 8e-6, 4e-6, 2e-6}) {
    const CollisionResult r = collide(1e5, dt, 0.0, etest::NormalLaw::Potential);
    const double x = std::log(dt), y = std::log(r.maxEnergyDrift);
    sx += x; sy += y; sxx += x * x; sxy += x * y; ++n;
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  std::cout << "[collision] order of the energy error in dt: " << slope << "\n";
  EXPECT_GT(slope, 1.7);
  EXPECT_LT(slope, 2.5);
}

// An ellipsoid dropped tilted on a frictionless plane under gravity, with Cundall local damping
// or [O]'s viscous damping, comes to rest lying on its largest face (c axis vertical) with the
// overlap m g/kn; its centre does not move sideways (no horizontal force).
TEST(EllipsoidOnPlane, ComesToRestWithStaticOverlapMgOverKn) {
  for (rotation::Damping damping : {rotation::Damping::Local, rotation::Damping::Viscous}) {
    Body e = Body::ellipsoid(Vec3(3e-3, 2e-3, 1e-3), 2600.0);
    e.q = Quat(Eigen::AngleAxisd(0.5, Vec3(1, 0.4, 0).normalized()));
    const double kn = 1e5, g = 9.81;
    const Vec3 m = Vec3::UnitZ(), p = Vec3::Zero();
    e.x = Vec3(1e-4, -2e-4, std::sqrt(e.shape().quadratic(m)) + 1e-5);
    const Vec3 x0 = e.x;
    const double dtc = ellipsoidCriticalTimeStep(e.m, e.inertia, e.axes, kn, 0.0, 0.0);
    const double dt = 0.2 * dtc;
    // Local damping 0.3; viscous: alpha = 60/s, near critical for the rocking of the grain on its
    // face (tens of rad/s), light for the contact's vertical mode (~4e4 rad/s).
    const double alpha = damping == rotation::Damping::Local ? 0.3 : 60.0;
    double overlap = 0.0;
    for (int step = 0; step < 3000000; ++step) {
      const EllipsoidPlaneContact c = ellipsoidPlane(e.x, e.shape(), p, m);
      Vec3 f = e.m * Vec3(0, 0, -g), t = Vec3::Zero();
      if (c.touching) {
        const Vec3 fn = kn * c.geometry.overlap * m;
        f += fn;
        t = c.geometry.branchB.cross(fn);
      }
      overlap = c.geometry.overlap;
      e.advance(f, t, dt, damping, alpha);
      if (step > 1000 && e.v.norm() < 1e-12 && e.w.norm() < 1e-9) break;
    }
    const double expected = e.m * g / kn;
    std::cout << "[rest on plane] overlap / (m g/kn) = " << overlap / expected << "\n";
    EXPECT_NEAR(overlap / expected, 1.0, 1e-6);
    EXPECT_GT(std::abs((e.q * Vec3::UnitZ()).z()), 1.0 - 1e-9);
    EXPECT_LT((e.x - x0).head<2>().norm(), 1e-12);
  }
}

// The critical time step against the exact largest eigenfrequency of one ellipsoid-plane contact
// with normal and shear springs (six degrees of freedom: Hessian of the normal energy by finite
// differences, shear stiffness ks J^T P_t J at the contact point, mass matrix m and I_world):
// dt_c w_max stays near 1, below leapfrog's stability limit 2, for every orientation tried.
TEST(EllipsoidTimeStep, CriticalStepBoundsTheContactEigenfrequency) {
  std::mt19937_64 rng(31);
  const Vec3 axes(3.0, 1.5, 1.0);
  const double rho = 1.0, kn = 1.0, ks = 0.3;
  const Body e0 = Body::ellipsoid(axes, rho);
  double lo = 1e9, hi = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const Quat q = etest::randomRotation(rng);
    const Vec3 m = Vec3::UnitZ();
    const Vec3 x(0, 0, std::sqrt(shapeMatrix(axes, q).quadratic(m)) - 1e-3);
    auto energy = [&](const Eigen::Matrix<double, 6, 1>& d) {
      const Quat qd = rotation::rotationQuaternion(d.tail<3>()) * q;
      return kn * ellipsoidPlane(x + d.head<3>(), shapeMatrix(axes, qd), Vec3::Zero(), m).energyOverKn;
    };
    Eigen::Matrix<double, 6, 6> k;
    const double h = 1e-4;
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) {
        Eigen::Matrix<double, 6, 1> di = Eigen::Matrix<double, 6, 1>::Zero(), dj = di;
        di[i] = h;
        dj[j] = h;
        k(i, j) = (energy(di + dj) - energy(di - dj) - energy(dj - di) + energy(-di - dj)) / (4 * h * h);
      }
    }
    const EllipsoidPlaneContact c = ellipsoidPlane(x, shapeMatrix(axes, q), Vec3::Zero(), m);
    Eigen::Matrix<double, 3, 6> j;
    Mat3 skew;
    const Vec3 b = c.geometry.branchB;
    skew << 0, -b.z(), b.y(), b.z(), 0, -b.x(), -b.y(), b.x(), 0;
    j << Mat3::Identity(), -skew;  // velocity of the contact point: v + w x b = v - [b]x w
    const Mat3 pt = Mat3::Identity() - m * m.transpose();
    k += ks * j.transpose() * pt * j;
    Eigen::Matrix<double, 6, 6> mass = Eigen::Matrix<double, 6, 6>::Zero();
    mass.topLeftCorner<3, 3>() = e0.m * Mat3::Identity();
    const Mat3 r = q.toRotationMatrix();
    mass.bottomRightCorner<3, 3>() = r * e0.inertia.asDiagonal() * r.transpose();
    const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(0.5 * (k + k.transpose()), mass);
    const double wMax = std::sqrt(es.eigenvalues().maxCoeff());
    const double ratio = ellipsoidCriticalTimeStep(e0.m, e0.inertia, axes, kn, ks, 0.0) * wMax;
    lo = std::min(lo, ratio);
    hi = std::max(hi, ratio);
  }
  std::cout << "[critical step] dt_c * w_max over orientations: " << lo << " .. " << hi << "\n";
  EXPECT_LT(hi, 1.2);  // leapfrog is stable below 2
  EXPECT_GT(lo, 0.5);  // and not needlessly small
}

// Rigid-body rotation kernels (core/rigid_rotation.hpp) against independent numbers: uniform
// rotation of an isotropic body, a fine Runge–Kutta solution of Euler's equations, the
// intermediate-axis growth rate, the closed-form decay of the midpoint viscous scheme.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "core/rigid_rotation.hpp"

using namespace grainlab;
using namespace grainlab::rotation;

namespace {

struct Rotor {
  Quat q;
  Vec3 w;  // world, mid-step
  Vec3 inertia;
};

// n torque-free steps.
void freeSteps(Rotor& r, double dt, int n) {
  for (int i = 0; i < n; ++i) {
    const LeapfrogRotation s = leapfrogRotation(r.q, r.w, r.inertia, Vec3::Zero(), dt, dt, Damping::None, 0.0);
    ASSERT_TRUE(s.step.converged);
    r.q = s.step.orientation;
    r.w = s.step.angularVelocity;
  }
}

Rotor startRotor(const Quat& q0, const Vec3& omegaBody0, const Vec3& inertia, double dt) {
  return {q0, startingMidStepOmega(q0, q0 * omegaBody0, inertia, dt), inertia};
}

// Euler's equations in the body frame, I w' = -w x I w, and q' = q (0, w)/2, by classical RK4
// with a fine step: the reference solution.
Quat referenceOrientation(const Quat& q0, const Vec3& omegaBody0, const Vec3& inertia, double t, int steps) {
  using State = Eigen::Matrix<double, 7, 1>;
  auto rate = [&](const State& y) {
    const Vec3 w = y.head<3>();
    const Quat q(y[3], y[4], y[5], y[6]);
    State d;
    d.head<3>() = (-w.cross(inertia.cwiseProduct(w))).cwiseQuotient(inertia);
    const Quat qd = q * Quat(0.0, w.x(), w.y(), w.z());
    d[3] = 0.5 * qd.w();
    d[4] = 0.5 * qd.x();
    d[5] = 0.5 * qd.y();
    d[6] = 0.5 * qd.z();
    return d;
  };
  State y;
  y << omegaBody0, q0.w(), q0.x(), q0.y(), q0.z();
  const double h = t / steps;
  for (int i = 0; i < steps; ++i) {
    const State k1 = rate(y), k2 = rate(y + 0.5 * h * k1), k3 = rate(y + 0.5 * h * k2), k4 = rate(y + h * k3);
    y += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return Quat(y[3], y[4], y[5], y[6]).normalized();
}

double angleBetween(const Quat& a, const Quat& b) {
  return 2.0 * std::asin(std::min(1.0, (a.conjugate() * b).vec().norm()));
}

}  // namespace

// Equal moments: w is constant and q^n = exp(n w dt) q^0 exactly (one fixed-point pass).
TEST(RigidRotation, IsotropicBodyTurnsUniformly) {
  const Vec3 w(0.3, -1.2, 0.7);
  Rotor r{Quat(Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized())), w, Vec3::Constant(2.5)};
  const Quat q0 = r.q;
  const double dt = 1e-3;
  freeSteps(r, dt, 1000);
  EXPECT_LT((r.w - w).norm(), 1e-13);
  EXPECT_LT(angleBetween(r.q, rotationQuaternion(1000 * dt * w) * q0), 1e-12);
}

// Torque-free triaxial body: the world angular momentum rebuilt from the stored state stays L0 to
// round-off over 1e5 steps (it drifts by at most 1e-15 relative per step: the rebuild repeats the
// same roundings every step), the energy L.w/2 oscillates at O((w dt)^2) without drift.
TEST(RigidRotation, TorqueFreeConservesAngularMomentumAndEnergy) {
  const Vec3 inertia(1.0, 2.0, 3.0), wb(0.4, 1.0, -0.6);
  const Quat q0(Eigen::AngleAxisd(1.0, Vec3(0.2, -1, 0.5).normalized()));
  const double dt = 1e-3;
  Rotor r = startRotor(q0, wb, inertia, dt);
  const Vec3 l0 = q0 * inertia.cwiseProduct(wb);
  const double e0 = 0.5 * wb.dot(inertia.cwiseProduct(wb));
  double worstE = 0.0, worstEFirst = 0.0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    freeSteps(r, dt, 1);
    const Vec3 l = midStepAngularMomentum(r.q, r.w, inertia, dt);
    ASSERT_LT((l - l0).norm(), 1e-15 * (i + 1) * l0.norm()) << "step " << i;
    if (i == n - 1) std::cout << "[torque-free] |L - L0|/|L0| after " << n << " steps: " << (l - l0).norm() / l0.norm() << "\n";
    const double err = std::abs(rotationalKineticEnergy(l, r.w) - e0) / e0;
    worstE = std::max(worstE, err);
    if (i < n / 10) worstEFirst = worstE;
  }
  std::cout << "[torque-free, |w| dt ~ 1.2e-3] energy error max " << worstE << " (first tenth " << worstEFirst << ")\n";
  EXPECT_LT(worstE, 1e-6);
  EXPECT_LT(worstE, 1.5 * worstEFirst);  // bounded, no drift
}

// With L stored (leapfrogRotationWithMomentum, one-pass tolerance): L is exactly constant for a
// torque-free body, one fixed-point pass per step at |w| dt ~ 1e-4, and the orientation follows
// the rebuilt-L variant to 1e-9 rad over 2e4 steps.
TEST(RigidRotation, StoredMomentumVariant) {
  const Vec3 inertia(1.0, 2.0, 3.0), wb(0.4, 1.0, -0.6);
  const Quat q0(Eigen::AngleAxisd(1.0, Vec3(0.2, -1, 0.5).normalized()));
  const double dt = 1e-4;
  Rotor rebuilt = startRotor(q0, wb, inertia, dt);
  Rotor stored = rebuilt;
  const Vec3 l0 = q0 * inertia.cwiseProduct(wb);
  Vec3 l = midStepAngularMomentum(stored.q, stored.w, inertia, dt);
  int passes = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const LeapfrogRotation s =
        leapfrogRotationWithMomentum(stored.q, stored.w, l, inertia, Vec3::Zero(), dt, Damping::None, 0.0);
    stored.q = s.step.orientation;
    stored.w = s.step.angularVelocity;
    l = s.angularMomentum;
    passes += s.step.iterations;
  }
  freeSteps(rebuilt, dt, n);
  EXPECT_LT((l - l0).norm(), 1e-15 * l0.norm());
  EXPECT_EQ(passes, n);
  EXPECT_LT(angleBetween(stored.q, rebuilt.q), 1e-9);
}

// Second order: the orientation error at t = 6 against a fine RK4 solution falls 4x per halving
// of dt.
TEST(RigidRotation, SecondOrderConvergenceOfFreeRotation) {
  const Vec3 inertia(1.0, 2.0, 3.0), wb(0.4, 1.0, -0.6);
  const Quat q0(Eigen::AngleAxisd(1.0, Vec3(0.2, -1, 0.5).normalized()));
  const double t = 6.0;
  const Quat ref = referenceOrientation(q0, wb, inertia, t, 200000);
  double prev = 0.0;
  for (int k = 0; k < 4; ++k) {
    const int n = 60 << k;
    const double dt = t / n;
    Rotor r = startRotor(q0, wb, inertia, dt);
    freeSteps(r, dt, n);
    const double err = angleBetween(r.q, ref);
    std::cout << "[convergence] dt " << dt << " orientation error " << err << " rad\n";
    if (k > 0) {
      EXPECT_NEAR(prev / err, 4.0, 0.4);
    }
    prev = err;
  }
}

// Intermediate-axis theorem: spin about the middle axis (I1 < I2 < I3) with a 1e-4 perturbation
// flips, at about ln(1/eps)/sigma with sigma = W sqrt((I2 - I1)(I3 - I2)/(I1 I3)); spin about
// the smallest and the largest axes stays there.
TEST(RigidRotation, IntermediateAxisInstability) {
  const Vec3 inertia(1.0, 2.0, 3.0);
  const double dt = 2e-3, eps = 1e-4;
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 wb = Vec3::Constant(eps);
    wb[axis] = 1.0;
    Rotor r = startRotor(Quat::Identity(), wb, inertia, dt);
    const Vec3 l0 = inertia.cwiseProduct(wb);
    double minAlong = 1.0, flipTime = -1.0;
    for (int i = 0; i < 30000; ++i) {
      freeSteps(r, dt, 1);
      const Vec3 body = (r.q.conjugate() * l0).cwiseQuotient(inertia);
      const double along = body[axis] / body.norm();
      minAlong = std::min(minAlong, along);
      if (flipTime < 0 && along < 0) flipTime = (i + 1) * dt;
    }
    if (axis == 1) {
      const double sigma = std::sqrt((inertia[1] - inertia[0]) * (inertia[2] - inertia[1]) / (inertia[0] * inertia[2]));
      const double expected = std::log(1.0 / eps) / sigma;
      std::cout << "[intermediate axis] first flip at t = " << flipTime << " (ln(1/eps)/sigma = " << expected << ")\n";
      ASSERT_GT(flipTime, 0.0);
      EXPECT_GT(flipTime, 0.7 * expected);
      EXPECT_LT(flipTime, 1.5 * expected);
      EXPECT_LT(minAlong, -0.99);  // fully reversed
    } else {
      EXPECT_GT(minAlong, 0.999);
    }
  }
}

// The rebuilt L^(n+1/2) equals the one the step was taken with, for a large torque kick too.
TEST(RigidRotation, StoredStateRebuildsTheAngularMomentum) {
  const Vec3 inertia(0.5, 2.0, 4.0);
  const Quat q(Eigen::AngleAxisd(2.0, Vec3(1, 1, 0).normalized()));
  const Vec3 w(0.3, -0.8, 2.0), torque(10.0, -3.0, 4.0);
  const double dt = 1e-2;
  const LeapfrogRotation s = leapfrogRotation(q, w, inertia, torque, dt, dt, Damping::None, 0.0);
  ASSERT_TRUE(s.step.converged);
  EXPECT_LT((midStepAngularMomentum(q, w, inertia, dt) + dt * torque - s.angularMomentum).norm(), 1e-14);
  EXPECT_LT((midStepAngularMomentum(s.step.orientation, s.step.angularVelocity, inertia, dt) - s.angularMomentum).norm(),
            1e-14 * s.angularMomentum.norm());
  std::cout << "[rotation step] |w| dt = " << s.step.angularVelocity.norm() * dt << ": " << s.step.iterations
            << " fixed-point passes\n";
}

// [O]'s midpoint viscous scheme: torque-free, L decays by exactly ((1 - a dt/2)/(1 + a dt/2))^n,
// within O(dt^2) of exp(-a t); under a constant force the momentum settles at F/alpha.
TEST(RigidRotation, ViscousMidpointDamping) {
  const Vec3 inertia(1.0, 2.0, 3.0);
  const double alpha = 5.0, dt = 1e-3;
  Rotor r = startRotor(Quat::Identity(), Vec3(0.4, 1.0, -0.6), inertia, dt);
  const Vec3 l0 = midStepAngularMomentum(r.q, r.w, inertia, dt);
  const int n = 400;
  for (int i = 0; i < n; ++i) {
    const LeapfrogRotation s = leapfrogRotation(r.q, r.w, inertia, Vec3::Zero(), dt, dt, Damping::Viscous, alpha);
    r.q = s.step.orientation;
    r.w = s.step.angularVelocity;
  }
  const double factor = std::pow((1 - 0.5 * alpha * dt) / (1 + 0.5 * alpha * dt), n);
  const Vec3 l = midStepAngularMomentum(r.q, r.w, inertia, dt);
  EXPECT_LT((l - factor * l0).norm(), 1e-13 * l0.norm());
  EXPECT_NEAR(factor / std::exp(-alpha * n * dt), 1.0, alpha * alpha * alpha * dt * dt * n * dt / 12 * 1.01);
  Vec3 p = Vec3::Zero();
  const Vec3 f(2.0, -1.0, 0.5);
  for (int i = 0; i < 20000; ++i) p = viscousMidpointKick(p, f, alpha, dt).momentum;
  EXPECT_LT((p - f / alpha).norm(), 1e-12);
}

TEST(RigidRotation, LocalDampingOpposesEachComponentOfTheMotion) {
  const Vec3 t(2.0, -3.0, 0.5), w(-1.0, -2.0, 0.0);
  const Vec3 td = localDamping(t, w, 0.3);
  EXPECT_DOUBLE_EQ(td.x(), 0.6);   // w_x < 0: pushes +
  EXPECT_DOUBLE_EQ(td.y(), 0.9);
  EXPECT_DOUBLE_EQ(td.z(), 0.0);   // w_z = 0: no damping
}

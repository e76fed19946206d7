// The leapfrog with Cundall local damping (docs/physics.md §5) on one body under a constant load,
// against the closed form of the damped scheme: per component, the load F is replaced by
// F - alpha sgn(v) |F| with v the mid-step velocity, so
//   v_{n+1} = v_n + (1 - alpha) F dt / m   while v_n and F have the same sign (damping resists the
//                                           acceleration),
//   v_{n+1} = v_n + (1 + alpha) F dt / m   while they have opposite signs (damping helps the
//                                           deceleration),
//   v_{n+1} = v_n + F dt / m               at v_n = 0 exactly, and for alpha = 0 always,
// and x_{n+1} = x_n + v_{n+1} dt. A body thrown against the load first decelerates at (1 + alpha)
// F/m, reverses and then accelerates at (1 - alpha) F/m: the step where it reverses is known in
// closed form, so every step of the sequence is checked, for a force (gravity) and for a torque
// (a contact moment held at its plastic limit).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>

#include "test_helpers.hpp"

using namespace grainlab;

namespace {

// Closed-form velocity after n steps of a body starting at v0 under a constant load with
// acceleration a (opposing v0 when v0 * a < 0) and damping alpha.
struct DampedSequence {
  double v0, a, alpha, dt;
  // Steps taken while v (before the step) still had the sign of v0: the smallest n with
  // v0 + n (1 + alpha) a dt of the opposite sign or zero.
  long reversal() const {
    if (v0 == 0.0 || v0 * a > 0.0) return 0;
    return static_cast<long>(std::ceil(std::abs(v0) / ((1.0 + alpha) * std::abs(a) * dt)));
  }
  double velocity(long n) const {
    if (v0 * a > 0.0) return v0 + n * (1.0 - alpha) * a * dt;  // same sign from the start
    if (v0 == 0.0) return n == 0 ? 0.0 : a * dt + (n - 1) * (1.0 - alpha) * a * dt;
    const long r = reversal();
    if (n <= r) return v0 + n * (1.0 + alpha) * a * dt;
    return v0 + r * (1.0 + alpha) * a * dt + (n - r) * (1.0 - alpha) * a * dt;
  }
  // Distance of v0 / ((1 + alpha) a dt) from an integer: the reversal step is unambiguous only
  // when this is not at round-off level.
  double reversalMargin() const {
    const double s = std::abs(v0) / ((1.0 + alpha) * std::abs(a) * dt);
    return std::abs(s - std::round(s));
  }
};

// One sphere thrown upwards against gravity in an empty box; it also moves sideways, where no
// force acts, so no damping either.
void checkFreeFlight(double alpha) {
  SCOPED_TRACE(::testing::Message() << "alpha = " << alpha);
  Simulation sim = scenes::emptyScene(1.0);
  sim.localDamping = alpha;
  sim.gravity = Vec3(0, 0, -9.81);
  sim.particles.addSphere(Vec3::Zero(), 1e-3, 2600.0);
  const double vz0 = 1.0, vx0 = 0.3, dt = 1e-4;
  sim.particles.velocity[0] = Vec3(vx0, 0, vz0);
  sim.initialise();
  sim.dt = dt;
  const DampedSequence seq{vz0, -9.81, alpha, dt};
  ASSERT_GT(seq.reversalMargin(), 1e-3);
  ASSERT_GT(seq.reversal(), 100);  // both phases are long
  double z = 0.0;                  // x_{n+1} = x_n + v_{n+1} dt, summed here
  double top = 0.0;
  for (long n = 1; n <= 2000; ++n) {
    sim.step();
    const double vz = seq.velocity(n);
    z += vz * dt;
    ASSERT_NEAR(sim.particles.velocity[0].z(), vz, 1e-12) << "step " << n;
    ASSERT_NEAR(sim.particles.position[0].z(), z, 1e-12) << "step " << n;
    ASSERT_EQ(sim.particles.velocity[0].x(), vx0) << "step " << n;
    top = std::max(top, sim.particles.position[0].z());
  }
  // The highest point of the damped flight is v0^2 / (2 (1 + alpha) g) up to O(v0 dt) (the
  // undamped flight would reach v0^2 / (2 g)).
  EXPECT_NEAR(top, vz0 * vz0 / (2.0 * (1.0 + alpha) * 9.81), vz0 * dt);
}

}  // namespace

TEST(CundallDamping, ForceClosedFormSequence) {
  omp_set_num_threads(1);
  checkFreeFlight(0.3);
  checkFreeFlight(0.7);
}

// Undamped: v = v0 + F t / m and x = x0 + v0 t + F t^2 / (2 m) + F t dt / (2 m) (the leapfrog's
// positions use the velocity at the end of each step).
TEST(CundallDamping, OffGivesUniformAcceleration) {
  omp_set_num_threads(1);
  Simulation sim = scenes::emptyScene(1.0);
  sim.gravity = Vec3(0, 0, -9.81);
  sim.particles.addSphere(Vec3::Zero(), 1e-3, 2600.0);
  sim.initialise();
  sim.dt = 1e-4;
  for (int n = 1; n <= 3000; ++n) {
    sim.step();
    const double t = n * sim.dt;
    ASSERT_NEAR(sim.particles.velocity[0].z(), -9.81 * t, 1e-12 * 9.81 * t) << "step " << n;
    ASSERT_NEAR(sim.particles.position[0].z(), -0.5 * 9.81 * t * (t + sim.dt), 1e-11) << "step " << n;
  }
}

// The same for a torque. Sphere A is held (infinite mass and inertia) and spins at -Omega about the
// contact normal; sphere B touches it with a fixed overlap (infinite mass, finite inertia I) and
// spins at +w0. The relative twist is so fast that the Kozicki–Donzé moment saturates in the first
// step at M = eta (RA + RB)/2 |Fn| along +N; B receives -M, a constant torque opposing its spin
// until it reverses, then driving it. With a tangential axis the same holds for bending (the
// branch vectors are parallel to N, so spin about N moves no contact point and Fs stays zero).
TEST(CundallDamping, TorqueClosedFormSequence) {
  omp_set_num_threads(1);
  for (const double alpha : {0.0, 0.3}) {
    SCOPED_TRACE(::testing::Message() << "alpha = " << alpha);
    Simulation sim = scenes::emptyScene(1.0);
    sim.localDamping = alpha;
    const double R = 1e-3, overlap = 1e-6, inertiaB = 1e-6, dt = 1e-5;
    sim.particles.addSphere(Vec3::Zero(), R, 2600.0);
    sim.particles.addSphere(Vec3(0, 0, 2 * R - overlap), R, 2600.0);
    sim.particles.setMass(0, 1e300, 1e300);
    sim.particles.setMass(1, 1e300, inertiaB);
    const double omegaA = -1e4, w0 = 100.0;
    sim.particles.angularVelocity[0] = Vec3(0, 0, omegaA);
    sim.particles.angularVelocity[1] = Vec3(0, 0, w0);
    sim.initialise();
    sim.dt = dt;
    // By hand: Kn = 2 Ec R R/(R + R) = Ec R = 3e7 N/m, |Fn| = Kn U = 30 N, limit = eta R |Fn| =
    // 0.03 N m; Kr = beta nu Kn R^2 = 1.35 N m/rad, so one step of relative twist (1e4 rad/s x 1e-5 s)
    // would load Kr x 0.1 = 0.135 N m > limit: plastic from the first step.
    const double limit = 1.0 * 0.5 * (R + R) * (30e9 * R) * overlap;
    ASSERT_NEAR(limit, 0.03, 1e-12);
    const DampedSequence seq{w0, -limit / inertiaB, alpha, dt};
    if (alpha > 0.0) ASSERT_GT(seq.reversalMargin(), 1e-3);
    for (long n = 1; n <= 800; ++n) {
      sim.step();
      ASSERT_NEAR(sim.particles.torque[1].z(), -limit, 1e-12 * limit) << "step " << n;
      ASSERT_NEAR(sim.particles.angularVelocity[1].z(), seq.velocity(n), 1e-9) << "step " << n;
      ASSERT_EQ(sim.particles.angularVelocity[1].x(), 0.0);
      ASSERT_EQ(sim.particles.angularVelocity[1].y(), 0.0);
    }
    // Reversed and accelerating the other way by now.
    EXPECT_LT(sim.particles.angularVelocity[1].z(), -10.0);
  }
}

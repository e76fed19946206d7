// Contact moments and Coulomb sliding at body level: through the engine's driver, the force and
// torque sums on the bodies and the integrator, against values worked out by hand.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "lab/protocols.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

namespace {

// Two spheres along x with a fixed overlap, both held (infinite mass and inertia) so that the
// spins the test prescribes are kept: A at the origin (radius rA), B at +x (radius rB).
struct PinnedPair {
  Simulation sim;
  double rA, rB, overlap;
  PinnedPair(contact::RollingLaw law, double rA_, double rB_, double overlap_)
      : sim(scenes::emptyScene(0.1)), rA(rA_), rB(rB_), overlap(overlap_) {
    sim.model.rolling = law;
    sim.particles.addSphere(Vec3::Zero(), rA, 2600.0);
    sim.particles.addSphere(Vec3(rA + rB - overlap, 0, 0), rB, 2600.0);
    for (std::size_t i = 0; i < 2; ++i) sim.particles.setMass(i, 1e300, 1e300);
    sim.initialise();
    sim.dt = 1e-6;
  }
  // Spins about z that roll B on A without slip at the contact point: omegaA x (C - xA) =
  // omegaB x (C - xB) with C - xA = (rA - U/2) ex and C - xB = -(rB - U/2) ex. Returns the
  // relative rotation rate of B with respect to A (about z).
  double rollWithoutSlip(double omegaB) {
    const double omegaA = -omegaB * (rB - 0.5 * overlap) / (rA - 0.5 * overlap);
    sim.particles.angularVelocity[0] = Vec3(0, 0, omegaA);
    sim.particles.angularVelocity[1] = Vec3(0, 0, omegaB);
    return omegaB - omegaA;
  }
};

}  // namespace

// Kozicki–Donzé ([W], docs/physics.md §4.1): bending. Hand numbers for rA = 1 mm, rB = 1.5 mm, U = 1 um:
// Kn = 2 Ec rA rB/(rA + rB) = 3.6e7 N/m, |Fn| = 36 N, Ks = 1.08e7 N/m, Kr = beta Ks rA rB =
// 2.43 N m/rad, limit eta (rA + rB)/2 |Fn| = 0.045 N m. B turns about +z relative to A, so the
// moment resists it: B receives -Kr dtheta ez (A the opposite), up to the limit, then stays there;
// when the relative rotation reverses the moment unloads elastically (slope Kr again).
TEST(BodyMoment, KozickiBendingElasticPlasticAndUnloading) {
  omp_set_num_threads(1);
  PinnedPair pair(contact::RollingLaw::KozickiDonze, 1e-3, 1.5e-3, 1e-6);
  Simulation& sim = pair.sim;
  const double kr = 2.43, limit = 0.045, dt = sim.dt;
  ASSERT_NEAR(sim.model.pairParams(1e-3, 1.5e-3).kn, 3.6e7, 1e-6);  // the hand numbers above
  const double rate = pair.rollWithoutSlip(10.0);  // 25.0 rad/s relative
  const long elasticSteps = static_cast<long>(limit / (kr * rate * dt));  // 740
  ASSERT_GT(elasticSteps, 500);
  double moment = 0.0;
  for (long n = 1; n <= 1200; ++n) {
    sim.step();
    moment = std::min(kr * rate * dt * n, limit);
    ASSERT_NEAR(sim.particles.torque[1].z(), -moment, 1e-9 * limit) << "step " << n;
    ASSERT_NEAR(sim.particles.torque[0].z(), moment, 1e-9 * limit) << "step " << n;
    // Rolling without slip loads no shear spring: B feels only the normal force, +x.
    ASSERT_NEAR(sim.particles.force[1].x(), 36.0, 1e-9);
    ASSERT_LT(sim.particles.force[1].tail<2>().norm(), 1e-9);
  }
  ASSERT_EQ(moment, limit);
  // Reverse: the moment unloads from the limit with the elastic slope and reloads to -limit.
  pair.rollWithoutSlip(-10.0);
  for (long n = 1; n <= 2000; ++n) {
    sim.step();
    const double expected = std::max(limit - kr * rate * dt * n, -limit);
    ASSERT_NEAR(sim.particles.torque[1].z(), -expected, 1e-9 * limit) << "step " << n;
  }
}

// Kozicki–Donzé resists twisting (spin of B about the normal) with the same Kr and limit.
TEST(BodyMoment, KozickiTwisting) {
  omp_set_num_threads(1);
  PinnedPair pair(contact::RollingLaw::KozickiDonze, 1e-3, 1.5e-3, 1e-6);
  Simulation& sim = pair.sim;
  sim.particles.angularVelocity[1] = Vec3(25.0, 0, 0);
  for (long n = 1; n <= 1200; ++n) {
    sim.step();
    const double expected = std::min(2.43 * 25.0 * sim.dt * n, 0.045);
    ASSERT_NEAR(sim.particles.torque[1].x(), -expected, 1e-9 * 0.045) << "step " << n;
    ASSERT_NEAR(sim.particles.torque[0].x(), expected, 1e-9 * 0.045) << "step " << n;
  }
}

// Linear rolling resistance ([R], docs/physics.md §4.2): bending only. R = rA rB/(rA + rB) = 0.6 mm,
// kr = Ks R^2 = 1.08e7 x 3.6e-7 = 3.888 N m/rad, limit mu_r |Fn| R with mu_r = min(0.3, 0.1) = 0.1:
// 0.1 x 36 x 6e-4 = 2.16e-3 N m. Twisting meets no resistance at all.
TEST(BodyMoment, RollingLinearBendingOnlyNoTwisting) {
  omp_set_num_threads(1);
  PinnedPair pair(contact::RollingLaw::Linear, 1e-3, 1.5e-3, 1e-6);
  Simulation& sim = pair.sim;
  sim.particles.rollingFriction[0] = 0.3;
  sim.particles.rollingFriction[1] = 0.1;
  const double kr = 3.888, limit = 2.16e-3, dt = sim.dt;
  const double rate = pair.rollWithoutSlip(1.0);  // 2.5 rad/s: 222 elastic steps
  for (long n = 1; n <= 600; ++n) {
    sim.step();
    const double expected = std::min(kr * rate * dt * n, limit);
    ASSERT_NEAR(sim.particles.torque[1].z(), -expected, 1e-9 * limit) << "step " << n;
    ASSERT_NEAR(sim.particles.torque[0].z(), expected, 1e-9 * limit) << "step " << n;
  }
  PinnedPair twist(contact::RollingLaw::Linear, 1e-3, 1.5e-3, 1e-6);
  twist.sim.particles.rollingFriction.assign(2, 0.3);
  twist.sim.particles.angularVelocity[1] = Vec3(25.0, 0, 0);
  for (long n = 1; n <= 100; ++n) {
    twist.sim.step();
    ASSERT_EQ(twist.sim.particles.torque[1].norm(), 0.0) << "step " << n;
  }
}

// Coulomb sliding on a frictional wall (contact.wall_friction_deg, set up by the laboratory's
// configureSolver as a run would be). A sphere resting on the floor (overlap m g / Kn, in
// equilibrium) is launched at v0 along +x without spin, no rolling resistance (beta = 0), no
// damping. While it slides the wall's tangential force is mu Fn against the slip, so
//   v = v0 - mu g t,   omega_y = (5/2) mu g t / R      (torque R mu m g, I = 2/5 m R^2),
// until v = omega R at t* = 2 v0 / (7 mu g); it then rolls at v = 5/7 v0, having dissipated
// m v0^2 / 7 by slip.
TEST(WallFriction, SlidingSphereDeceleratesThenRolls) {
  omp_set_num_threads(1);
  lab::RunConfig c;
  c.contact.wallFrictionDeg = 20.0;
  c.contact.beta = 0.0;
  c.solver.damping = 0.0;
  Simulation sim;
  // Floor at z = 0: the equilibrium overlap m g / Kn is only 1.8e-12 m, so the sphere's height must
  // be a small number for it to be represented to 1e-7.
  sim.box.setBounds(Vec3(-0.05, -0.05, 0.0), Vec3(0.05, 0.05, 0.1));
  const double R = 1e-3, g = 9.81, v0 = 0.2;
  sim.particles.addSphere(Vec3(0, 0, R), R, 2600.0);
  c.sample.gravity = std::array<double, 3>{0.0, 0.0, -g};  // configureSolver sets sim.gravity from it
  lab::configureSolver(c, sim);
  const double mu = std::tan(20.0 * kPi / 180.0);
  const double m = sim.particles.mass[0];
  const double kn = 2.0 * 30e9 * R;
  sim.particles.position[0] = Vec3(0, 0, R - m * g / kn);
  sim.particles.velocity[0] = Vec3(v0, 0, 0);
  const double tStar = 2.0 * v0 / (7.0 * mu * g);
  const long slidingSteps = static_cast<long>(tStar / sim.dt);
  ASSERT_GT(slidingSteps, 10000);
  for (long n = 1; n <= slidingSteps - 10; ++n) {
    sim.step();
    const Vec3 f = sim.particles.force[0];  // the wall contact is the only contact
    ASSERT_NEAR(f.z() / (m * g), 1.0, 1e-5) << "step " << n;
    ASSERT_NEAR(f.x(), -mu * f.z(), 1e-12 * f.z()) << "step " << n;  // at the limit, against +x slip
    ASSERT_EQ(f.y(), 0.0);
    if (n % 1000 == 0) {
      const double t = n * sim.dt;
      ASSERT_NEAR(sim.particles.velocity[0].x(), v0 - mu * g * t, 1e-6 * v0) << "step " << n;
      ASSERT_NEAR(sim.particles.angularVelocity[0].y() * R, 2.5 * mu * g * t, 1e-6 * v0) << "step " << n;
    }
  }
  for (long n = 0; n < slidingSteps; ++n) sim.step();
  EXPECT_NEAR(sim.particles.velocity[0].x() / v0, 5.0 / 7.0, 1e-3);
  EXPECT_NEAR(sim.particles.angularVelocity[0].y() * R / v0, 5.0 / 7.0, 1e-3);
  // Now rolling and sticking: the (undamped) tangential spring oscillates below the Coulomb limit
  // and slip dissipates nothing more.
  const double slipRolling = sim.energy.slip;
  for (long n = 0; n < 2000; ++n) {
    sim.step();
    ASSERT_LT(std::abs(sim.particles.force[0].x()), mu * sim.particles.force[0].z());
  }
  EXPECT_EQ(sim.energy.slip, slipRolling);
  EXPECT_NEAR(sim.energy.slip / (m * v0 * v0 / 7.0), 1.0, 1e-3);
}

// Two-body cases through the whole engine (driver + kernels + integrator), against analytic values.
#include <gtest/gtest.h>

#include <omp.h>

#include <cmath>

#include "test_helpers.hpp"

using namespace grainlab;

// Head-on collision, no damping: a linear spring of stiffness Kn = 2 Ec R R/(R + R) between two
// spheres of reduced mass m* = m/2 gives a contact lasting pi sqrt(m*/Kn), restitution 1, and
// kinetic + spring energy conserved.
TEST(HeadOnCollision, DurationRestitutionEnergy) {
  Simulation sim = scenes::emptyScene();
  const double R = 1e-3, rho = 2600.0, v0 = 0.1;
  sim.particles.addSphere(Vec3(-R - 1e-8, 0, 0), R, rho);
  sim.particles.addSphere(Vec3(R + 1e-8, 0, 0), R, rho);
  sim.particles.velocity[0] = Vec3(v0, 0, 0);
  sim.particles.velocity[1] = Vec3(-v0, 0, 0);
  sim.initialise();
  const double kn = 30e9 * R;  // Kn = 2 Ec R R/(R + R) [docs/physics.md §4.1], by hand
  const double m = sim.particles.mass[0];
  const double expected = kPi * std::sqrt(0.5 * m / kn);
  sim.dt = expected / 2000.0;
  const double e0 = m * v0 * v0;  // both spheres
  long start = -1, end = -1;
  double maxEnergyError = 0.0;
  for (int i = 0; i < 8000 && end < 0; ++i) {
    sim.step();
    const bool touching = sim.touchingPairs() == 1;
    if (touching && start < 0) start = sim.stepCount;
    if (!touching && start >= 0) end = sim.stepCount;
    // Leapfrog velocities live at half steps: average the kinetic energy of the two half steps
    // around the current positions by using the mean velocity.
    const Vec3 x0 = sim.particles.position[0], x1 = sim.particles.position[1];
    const double overlap = std::max(0.0, 2 * R - (x1 - x0).norm());
    const double kinetic = 0.5 * m * (sim.particles.velocity[0].squaredNorm() +
                                      sim.particles.velocity[1].squaredNorm());
    maxEnergyError = std::max(maxEnergyError, std::abs(kinetic + 0.5 * kn * overlap * overlap - e0) / e0);
  }
  ASSERT_GT(start, 0);
  ASSERT_GT(end, start);
  const double duration = (end - start) * sim.dt;
  EXPECT_NEAR(duration / expected, 1.0, 0.01);
  EXPECT_NEAR(-sim.particles.velocity[0].x() / v0, 1.0, 1e-3);  // restitution
  EXPECT_NEAR(sim.particles.velocity[1].x() / v0, 1.0, 1e-3);
  EXPECT_LT(maxEnergyError, 5e-3);
  // Momentum stays zero.
  EXPECT_NEAR((sim.particles.velocity[0] + sim.particles.velocity[1]).norm(), 0.0, 1e-12);
}

// A loaded contact carried round a quarter turn as a rigid body: the shear force keeps its length,
// stays in the tangent plane, and turns with the pair.
TEST(ShearForce, RigidRotationOfLoadedContact) {
  Simulation sim = scenes::emptyScene();
  const double R = 1e-3, overlap = 1e-6;
  sim.particles.addSphere(Vec3(-(R - 0.5 * overlap), 0, 0), R, 2600.0);
  sim.particles.addSphere(Vec3(R - 0.5 * overlap, 0, 0), R, 2600.0);
  for (std::size_t i = 0; i < 2; ++i) {  // immovable by forces: the test prescribes the motion
    sim.particles.setMass(i, 1e30, 1e30);
  }
  sim.initialise();
  sim.dt = 1e-7;
  // Load: B slides along +y for 100 steps at 1 mm/s (10 nm of tangential displacement).
  sim.particles.velocity[1] = Vec3(0, 1e-3, 0);
  for (int i = 0; i < 100; ++i) {
    sim.step();
    sim.particles.position[1].y() = 0.0;  // keep the geometry fixed while loading
  }
  sim.particles.velocity[1].setZero();
  sim.step();
  const Vec3 fs0 = sim.contacts.sphereSphere.force[0] - sim.contacts.sphereSphere.force[0].dot(Vec3::UnitX()) * Vec3::UnitX();
  const double ks = 0.3 * 30e9 * R;  // Ks = nu Kn, by hand
  EXPECT_NEAR(fs0.y(), -ks * 1e-8, 1e-6 * ks * 1e-8);  // elastic, opposing B's slip
  // Rigid rotation about z through the midpoint at Omega: each step the velocities are those of the
  // rigid motion at the current positions, and the positions are then set to the exact rotation.
  const double omega = 200.0;
  const int steps = static_cast<int>(std::round(0.5 * kPi / (omega * sim.dt)));
  const Vec3 xA0 = sim.particles.position[0], xB0 = sim.particles.position[1];
  for (int i = 1; i <= steps; ++i) {
    const Eigen::AngleAxisd rot(omega * sim.dt * i, Vec3::UnitZ());
    for (std::size_t b = 0; b < 2; ++b) {
      sim.particles.angularVelocity[b] = Vec3(0, 0, omega);
      sim.particles.velocity[b] = Vec3(0, 0, omega).cross(sim.particles.position[b]);
    }
    sim.step();
    sim.particles.position[0] = rot * xA0;
    sim.particles.position[1] = rot * xB0;
  }
  for (std::size_t b = 0; b < 2; ++b)
    sim.particles.velocity[b] = Vec3(0, 0, omega).cross(sim.particles.position[b]);
  // The normal at which the force is evaluated (positions move during the step).
  const Vec3 n = (sim.particles.position[1] - sim.particles.position[0]).normalized();
  sim.step();
  const Vec3 f = sim.contacts.sphereSphere.force[0];
  const Vec3 fs = f - f.dot(n) * n;
  EXPECT_NEAR(fs.norm() / fs0.norm(), 1.0, 1e-6);
  EXPECT_NEAR(std::abs(fs.normalized().dot(n)), 0.0, 1e-9);
  // Rotated with the pair: a quarter turn about z takes -y to +x.
  const Vec3 expectedDirection = Eigen::AngleAxisd(omega * sim.dt * steps, Vec3::UnitZ()) * fs0.normalized();
  EXPECT_NEAR((fs.normalized() - expectedDirection).norm(), 0.0, 1e-3);
}

// A sphere settling on the bottom wall under gravity: at rest, the wall carries its weight and the
// overlap is m g / Kn with Kn = 2 Ec R.
TEST(SphereOnWall, RestsUnderGravity) {
  Simulation sim = scenes::emptyScene(0.01);
  const double R = 1e-3;
  sim.particles.addSphere(Vec3(0, 0, -0.01 + R + 1e-5), R, 2600.0);
  sim.gravity = Vec3(0, 0, -9.81);
  sim.localDamping = 0.7;  // damping changes the approach, not the state of rest
  sim.initialise();
  sim.dt = 0.5 * sim.criticalTimeStep();
  omp_set_num_threads(1);  // one sphere: threads would only add overhead
  for (int i = 0; i < 60000; ++i) sim.step();
  const double m = sim.particles.mass[0];
  const Wall& bottom = sim.box.lower(2);
  EXPECT_NEAR(bottom.normalForce / (m * 9.81), 1.0, 1e-6);
  const double overlap = R - (sim.particles.position[0].z() - bottom.position);
  EXPECT_NEAR(overlap / (m * 9.81 / (2.0 * 30e9 * R)), 1.0, 1e-6);
  EXPECT_LT(sim.particles.velocity[0].norm(), 1e-9);
}

// Gravity (sample.gravity) against statics and the energy balance, computed by hand:
//   a sphere at rest on the floor: the floor carries m g;
//   a vertical column of N equal spheres at rest: the contact under sphere k (0 the lowest) carries
//   the weight of the N - k spheres above it, (N - k) m g, and the floor N m g;
//   an undamped sphere dropped onto the floor: kinetic + spring energy = the work of gravity
//   m g (z0 - z), booked exactly (the leapfrog moves a particle by v dt under the constant m g).
#include <gtest/gtest.h>

#include <cmath>

#include "core/contact_view.hpp"
#include "lab/measurements.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

namespace {

constexpr double kGravR = 1e-3, kGravRho = 2600.0, kGravity = 9.81, kL = 0.01;

double sphereMass() { return kGravRho * 4.0 / 3.0 * kPi * kGravR * kGravR * kGravR; }

Simulation column(int n, double damping) {
  Simulation sim = scenes::emptyScene(kL);
  sim.gravity = Vec3(0.0, 0.0, -kGravity);
  sim.localDamping = damping;
  sim.model.young = 3e7;  // soft: a longer time step, the same statics
  // Touching (no overlap): each sphere sinks into the one below by its share of the weight.
  for (int k = 0; k < n; ++k) sim.particles.addSphere(Vec3(0.0, 0.0, -kL + kGravR + 2.0 * kGravR * k), kGravR, kGravRho);
  sim.initialise();
  sim.dt = 0.2 * sim.criticalTimeStep();
  return sim;
}

double floorForce(const Simulation& sim) { return sim.box.walls[WallBox::index(2, 0)].normalForce; }

}  // namespace

TEST(Gravity, SphereAtRestOnTheFloorCarriesItsWeight) {
  Simulation sim = column(1, 0.3);
  for (int i = 0; i < 20000; ++i) sim.step();
  const double mg = sphereMass() * kGravity;
  EXPECT_NEAR(floorForce(sim) / mg, 1.0, 1e-6);
  EXPECT_NEAR(sim.particles.velocity[0].norm(), 0.0, 1e-6);
  // The walls that hold nothing carry nothing.
  EXPECT_EQ(sim.box.walls[WallBox::index(2, 1)].normalForce, 0.0);
  EXPECT_LT(lab::unbalancedForceRatio(sim), 1e-6);
}

TEST(Gravity, ColumnCarriesTheWeightAboveEachContact) {
  constexpr int n = 6;
  Simulation sim = column(n, 0.3);
  for (int i = 0; i < 60000; ++i) sim.step();
  const double mg = sphereMass() * kGravity;
  EXPECT_NEAR(floorForce(sim) / (n * mg), 1.0, 1e-6);
  int seen = 0;
  forEachTouchingContact(sim, [&](const ContactView& c) {
    if (c.wall) return;
    // Particles in storage order are the column from the floor up.
    const std::uint32_t lower = std::min(c.a, c.b);
    ASSERT_EQ(std::max(c.a, c.b), lower + 1);
    EXPECT_NEAR(c.force.norm() / ((n - 1 - lower) * mg), 1.0, 1e-6) << "contact above sphere " << lower;
    EXPECT_NEAR(std::abs(c.force.z()), c.force.norm(), 1e-12 * mg) << "a column's contact forces are vertical";
    ++seen;
  });
  EXPECT_EQ(seen, n - 1);
}

TEST(Gravity, UndampedDropClosesTheEnergyBalance) {
  Simulation sim = column(1, 0.0);
  const double z0 = sim.particles.position[0].z() + 5e-4;  // 0.5 mm above the floor
  sim.particles.position[0].z() = z0;
  sim.initialise();
  // omega dt = 0.02: the leapfrog's half-step velocities misstate the energy at a contact by about
  // omega dt / 2 of it.
  sim.dt = 0.02 * sim.criticalTimeStep();
  const double m = sphereMass();
  double worst = 0.0;
  bool bounced = false;
  for (int i = 0; i < 60000; ++i) {
    sim.step();
    const double z = sim.particles.position[0].z();
    // Gravity's work is m g times the fall, to round-off.
    ASSERT_NEAR(sim.energy.gravityWork, m * kGravity * (z0 - z), 1e-12 * m * kGravity * 5e-4) << "step " << i;
    const double stored = lab::kineticEnergy(sim) + lab::elasticEnergy(sim);
    worst = std::max(worst, std::abs(stored - sim.energy.gravityWork));
    bounced = bounced || sim.particles.velocity[0].z() > 0.0;
  }
  ASSERT_TRUE(bounced) << "the sphere should have hit the floor and bounced";
  EXPECT_LT(worst, 2e-2 * m * kGravity * 5e-4) << "slip " << sim.energy.slip << " rolling " << sim.energy.rolling
                                         << " damping " << sim.energy.damping << " worst/mgh " << worst / (m * kGravity * 5e-4)
                                         << " kinetic " << lab::kineticEnergy(sim) << " elastic " << lab::elasticEnergy(sim)
                                         << " W_g " << sim.energy.gravityWork << " z " << sim.particles.position[0].z();
}

// The critical time step (src/core/time_step.cpp, docs/physics.md §7) of a given small sample against
// sqrt(m/k) worked out by hand for both contact models.
//
// The engine takes, per sphere, the stiffest contact it can have (against a wall): translation
// sqrt(m / Kn) with Kn = 2 Ec R, rotation sqrt(I / (Ks R^2 + Kr)) (shear spring at arm R plus the
// rolling spring), I = 2/5 m R^2, and the minimum over the sample. For Ec = 30 GPa, nu = 0.3,
// rho = 2600 kg/m^3 and the smallest sphere R = 1 mm (m = 4/3 pi R^3 rho = 1.0891e-5 kg):
//   translation               sqrt(1.0891e-5 / 6e7)                          = 4.2604e-7 s
//   Kozicki (Kr = beta Ks R^2) sqrt(0.4 m / (0.3 x 6e7 x (1 + 0.15)))       = 4.5875e-7 s
//   rolling-linear (Kr = Ks R^2) sqrt(0.4 m / (2 x 0.3 x 6e7))               = 3.4786e-7 s
// so translation governs the Kozicki sample and rotation the rolling-linear one. The 2 mm sphere
// gives twice these (sqrt(m/R) grows as R) and does not count.
#include <gtest/gtest.h>

#include <cmath>

#include "test_helpers.hpp"

using namespace grainlab;

namespace {

Simulation sample(contact::RollingLaw law) {
  Simulation sim = scenes::emptyScene(0.1);
  sim.model.rolling = law;
  sim.particles.addSphere(Vec3(0.0, 0.0, 0.0), 2e-3, 2600.0);
  sim.particles.addSphere(Vec3(0.01, 0.0, 0.0), 1e-3, 2600.0);
  sim.particles.addSphere(Vec3(0.02, 0.0, 0.0), 1.5e-3, 2600.0);
  return sim;
}

}  // namespace

TEST(CriticalTimeStep, KozickiByHand) {
  const Simulation sim = sample(contact::RollingLaw::KozickiDonze);
  EXPECT_NEAR(sim.criticalTimeStep() / 4.2604488e-7, 1.0, 1e-7);
  // The same from the formula, for the smallest sphere.
  const double m = 4.0 / 3.0 * kPi * 1e-9 * 2600.0;
  EXPECT_NEAR(sim.criticalTimeStep() / std::sqrt(m / (2.0 * 30e9 * 1e-3)), 1.0, 1e-12);
}

TEST(CriticalTimeStep, RollingLinearByHand) {
  const Simulation sim = sample(contact::RollingLaw::Linear);
  EXPECT_NEAR(sim.criticalTimeStep() / 3.4786419e-7, 1.0, 1e-7);
  const double m = 4.0 / 3.0 * kPi * 1e-9 * 2600.0;
  const double ks = 0.3 * 2.0 * 30e9 * 1e-3;
  EXPECT_NEAR(sim.criticalTimeStep() / std::sqrt(0.4 * m * 1e-6 / (2.0 * ks * 1e-6)), 1.0, 1e-12);
}

// A heavier grain (setMass) is slower: the minimum moves to the next-smallest light one, which here
// is the 1.5 mm sphere: sqrt(m/Kn) scales as R, so 1.5 x 4.2604e-7 s.
TEST(CriticalTimeStep, FollowsTheMassOverride) {
  Simulation sim = sample(contact::RollingLaw::KozickiDonze);
  const double m = sim.particles.mass[1];
  sim.particles.setMass(1, 100.0 * m, 100.0 * sim.particles.inertia[1]);
  EXPECT_NEAR(sim.criticalTimeStep() / (1.5 * 4.2604488e-7), 1.0, 1e-7);
}

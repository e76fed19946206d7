// Conservation in a free cluster: contact forces sum to zero (Newton's third law), and contact
// forces and moments exert no net torque (angular momentum balance), at every step.
#include <gtest/gtest.h>

#include "lab/random.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

TEST(FreeCluster, NewtonThirdLawAndAngularMomentum) {
  Simulation sim = scenes::emptyScene(1.0);
  lab::Rng rng(7);
  // A 4x4x3 lattice of slightly overlapping spheres of unequal size with random velocities and
  // spins, so that normal, shear and moment springs all load; far from the walls.
  for (int i = 0; i < 48; ++i) {
    const double r = rng.uniform(1.0e-3, 1.002e-3);
    const Vec3 site(2e-3 * (i % 4), 2e-3 * ((i / 4) % 4), 2e-3 * (i / 16));
    sim.particles.addSphere(site + Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)) * 1e-6,
                            r, 2600.0);
    sim.particles.velocity.back() = Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)) * 1e-3;
    sim.particles.angularVelocity.back() = Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    // Massive bodies keep their prescribed motion, so the contacts stay closed while their shear
    // and moment springs load; the balance of the contact forces does not depend on the masses.
    sim.particles.setMass(sim.particles.size() - 1, 1e30, 1e30);
  }
  sim.initialise();
  sim.dt = 1e-5;
  int loadedSteps = 0;
  for (int s = 0; s < 300; ++s) {
    // Forces are evaluated at the positions before the step's integration.
    const std::vector<Vec3> x = sim.particles.position;
    sim.step();
    Vec3 total = Vec3::Zero(), torque = Vec3::Zero();
    double scale = 0.0, torqueScale = 0.0;
    for (std::size_t i = 0; i < sim.particles.size(); ++i) {
      const Vec3& f = sim.particles.force[i];
      total += f;
      torque += x[i].cross(f) + sim.particles.torque[i];
      scale += f.norm();
      torqueScale += x[i].norm() * f.norm() + sim.particles.torque[i].norm();
    }
    if (scale == 0.0) continue;
    ++loadedSteps;
    EXPECT_LT(total.norm(), 1e-12 * scale);
    EXPECT_LT(torque.norm(), 1e-12 * torqueScale);
  }
  EXPECT_EQ(loadedSteps, 300);
  EXPECT_GT(sim.touchingPairs(), 10u);
}

// Isotropic equilibrium in the wall box: the Love–Weber stress from contacts equals the stress the
// walls measure (PHYSICS.md §7.1), and the servo holds the target pressure.
#include <gtest/gtest.h>
#include <omp.h>

#include "lab/measurements.hpp"
#include "lab/protocols.hpp"

using namespace grainlab;

TEST(IsotropicEquilibrium, ContactStressEqualsWallStress) {
  lab::RunConfig c;
  c.sample.nParticles = 150;
  c.sample.grading.type = "uniform";
  c.sample.grading.dMin = 4e-3;
  c.sample.grading.dMax = 6e-3;
  c.sample.prepFrictionDeg = 20.0;
  c.test.confiningPressure = 100e3;
  omp_set_num_threads(2);
  lab::Laboratory lab(c);
  const lab::PreparationResult prep = lab.prepare();
  const Vec3 walls = prep.state.boundaryStress;
  const Mat3 contacts = prep.state.contactStress;
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(walls[a] / 100e3, 1.0, 0.01) << "axis " << a;
    EXPECT_NEAR(contacts(a, a) / walls[a], 1.0, 0.02) << "axis " << a;
  }
  // Smooth walls can still hold a couple (eccentric wall resultants), so in a sample only a few
  // grains wide sigma_xy need not vanish; moment balance of the assembly makes the tensor symmetric.
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b)
      EXPECT_LT(std::abs(contacts(a, b) - contacts(b, a)), 0.005 * 100e3);
  EXPECT_LT(prep.state.unbalanced, c.solver.unbalancedTolerance);
  EXPECT_GT(prep.e0, 0.3);
  EXPECT_LT(prep.e0, 1.2);
}

// A small sample in the wall box (lab::Laboratory): the Love–Weber stress from the contacts equals
// the stress the walls measure (docs/physics.md §9) at isotropic equilibrium and at a deviatoric
// state during drained triaxial compression. The identity behind it is statics: summed over every
// contact of every particle, f (x) (x_c - x_p) leaves only the wall contacts and the particles' net
// forces, and the wall terms are (wall force) x (box length) / V = the wall stress. So the two agree
// to the unbalanced force, and a wrong sign or arm of any contact force or of the stress sum shows.
#include <gtest/gtest.h>
#include <omp.h>

#include <memory>

#include "lab/measurements.hpp"
#include "lab/protocols.hpp"

using namespace grainlab;

class WallBoxSample : public ::testing::Test {
 protected:
  static lab::RunConfig config() {
    lab::RunConfig c;
    c.sample.nParticles = 150;
    c.sample.grading.type = "uniform";
    c.sample.grading.dMin = 4e-3;
    c.sample.grading.dMax = 6e-3;
    c.sample.prepFrictionDeg = 20.0;
    c.test.confiningPressure = 100e3;
    c.test.finalAxialStrain = 0.03;
    c.solver.maxSteps = 400000;  // a broken law fails here instead of running for hours
    return c;
  }
  static void SetUpTestSuite() {
    omp_set_num_threads(1);
    lab_ = std::make_unique<lab::Laboratory>(config());
    prep_ = std::make_unique<lab::PreparationResult>(lab_->prepare());
  }
  static void TearDownTestSuite() {
    lab_.reset();
    prep_.reset();
  }
  static std::unique_ptr<lab::Laboratory> lab_;
  static std::unique_ptr<lab::PreparationResult> prep_;
};
std::unique_ptr<lab::Laboratory> WallBoxSample::lab_;
std::unique_ptr<lab::PreparationResult> WallBoxSample::prep_;

TEST_F(WallBoxSample, IsotropicContactStressEqualsWallStress) {
  const Simulation& sim = lab_->simulation();
  const Vec3 walls = prep_->state.boundaryStress;
  const Mat3 contacts = prep_->state.contactStress;
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(contacts(a, a) / walls[a], 1.0, 0.02) << "axis " << a;
  // Smooth walls can still hold a couple (eccentric wall resultants), so in a sample only a few
  // grains wide sigma_xy need not vanish; moment balance of the assembly makes the tensor symmetric.
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b)
      EXPECT_LT(std::abs(contacts(a, b) - contacts(b, a)), 0.005 * 100e3);
  // Force balance of the whole sample: opposite walls push equally hard, to the unbalanced force.
  for (int a = 0; a < 3; ++a) {
    const double lower = sim.box.lower(a).normalForce, upper = sim.box.upper(a).normalForce;
    EXPECT_NEAR(lower / upper, 1.0, 0.02) << "axis " << a;
  }
  // The reported void ratio is the box's volume over the spheres' volume, minus one.
  double solid = 0.0;
  for (double r : sim.particles.radius) solid += 4.0 / 3.0 * kPi * r * r * r;
  EXPECT_NEAR(prep_->e0, sim.box.length(0) * sim.box.length(1) * sim.box.length(2) / solid - 1.0, 1e-12);
}

// The stress the boundary applies, computed here from the geometry alone: sigma = -(1/V) sum over
// wall contacts of f (x) x_c (the average-stress theorem, compression positive), with the smooth
// walls' force f = Kn U n_in, Kn = 2 Ec r, U = r - (distance of the centre from the wall), at the
// contact point x_c = x - (r - U/2) n_in. Its diagonal is the wall stresses; its off-diagonal terms
// are the couples of eccentric wall resultants, which in a box a few grains wide are not small.
Mat3 boundaryStress(const Simulation& sim) {
  Mat3 s = Mat3::Zero();
  for (std::size_t i = 0; i < sim.particles.size(); ++i) {
    const Vec3& x = sim.particles.position[i];
    const double r = sim.particles.radius[i];
    for (const Wall& w : sim.box.walls) {
      const double overlap = r - w.distance(x);
      if (overlap <= 0.0) continue;
      const Vec3 n = w.inwardNormal();
      s -= (2.0 * sim.model.young * r * overlap * n) * (x - (r - 0.5 * overlap) * n).transpose();
    }
  }
  return s / sim.box.volume();
}

// Sheared to 3 % axial strain (sigma1 about 6 sigma3), then held: platens stopped, lateral walls
// still servo-controlled, until the unbalanced force ratio is below 0.005. Every component of the
// Love–Weber tensor equals the boundary's within 2 % of the mean stress, and its normal components
// equal the wall stresses within 2 %.
TEST_F(WallBoxSample, DeviatoricContactStressEqualsWallStress) {
  lab::Laboratory lab = *lab_;
  const lab::ShearResult shear = lab.shear();
  Simulation& sim = lab.simulation();
  sim.box.lower(2).velocity = 0.0;
  sim.box.upper(2).velocity = 0.0;
  long held = 0;
  while (lab::unbalancedForceRatio(sim) > 0.005) {
    sim.step();
    ASSERT_LT(++held, 200000) << "no quasi-static state";
  }
  const Vec3 walls = lab::boundaryStress(sim);
  const Mat3 contacts = lab::contactStress(sim);
  const Mat3 boundary = boundaryStress(sim);
  ASSERT_GT(walls[2] / walls[0], 1.5) << "not a deviatoric state: the test would not test it";
  const double p = walls.sum() / 3.0;
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(contacts(a, a) / walls[a], 1.0, 0.02) << "axis " << a;
    // (Not exact: the two walls of an axis differ by the residual unbalanced force.)
    EXPECT_NEAR(boundary(a, a) / walls[a], 1.0, 0.01) << "axis " << a;
    for (int b = 0; b < 3; ++b) EXPECT_NEAR(contacts(a, b), boundary(a, b), 0.02 * p) << a << b;
  }
  // The time series' last record (while the platens still moved) satisfies the identity too, to
  // the few per cent its inertia allows.
  const lab::Record& last = shear.records.back();
  EXPECT_NEAR(last.sigma1Contact / last.sigma1, 1.0, 0.05);
  EXPECT_NEAR(last.eps1, 0.03, 0.001);
}

// Out of equilibrium the wall stress and the contact stress differ, and by exactly the stress of the
// grains' net contact forces (lab::unbalancedStress): the platens are driven 20x faster than the
// test's rate, so that the net forces are large, and at every one of 30 steps each normal component
// satisfies wall = contact + unbalanced to 0.2 % of p (a contact point lies half an overlap behind
// the wall plane), while the gap itself is several times larger (the check is not vacuous). A wrong
// sign, origin or arm in either sum breaks it.
TEST_F(WallBoxSample, WallStressIsContactStressPlusTheNetForcesStressOutOfEquilibrium) {
  lab::Laboratory lab = *lab_;
  lab.shear();
  Simulation& sim = lab.simulation();
  const double speed = 20.0 * std::abs(sim.box.upper(2).velocity) + 1e-4;
  sim.box.lower(2).velocity = speed;
  sim.box.upper(2).velocity = -speed;
  double largestGap = 0.0;
  for (int k = 0; k < 30; ++k) {
    sim.step();
    const Vec3 walls = lab::boundaryStress(sim);
    const Mat3 contacts = lab::contactStress(sim);
    const Mat3 unbalanced = lab::unbalancedStress(sim);
    const double p = walls.sum() / 3.0;
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(walls[a], contacts(a, a) + unbalanced(a, a), 2e-3 * p) << "step " << k << " axis " << a;
      largestGap = std::max(largestGap, std::abs(walls[a] - contacts(a, a)) / p);
    }
  }
  EXPECT_GT(largestGap, 0.01) << "the sample stayed in equilibrium: the identity was not tested";
  // In a periodic cell the boundary stress is the contact stress: nothing is left over.
  Simulation cell;
  cell.boundary = Boundary::Periodic;
  EXPECT_EQ(lab::unbalancedStress(cell), Mat3::Zero());
}

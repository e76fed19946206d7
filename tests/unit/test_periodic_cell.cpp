// The periodic cell (docs/physics.md §8.2) against independent expectations: affine motion, images
// across faces, history through wrapping, momentum, rigid rotation, the servo, size limits.
#include <gtest/gtest.h>

#include <cmath>

#include "core/contact_view.hpp"
#include "core/errors.hpp"
#include "lab/measurements.hpp"
#include "lab/protocols.hpp"
#include "lab/random.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

namespace {

// An empty periodic simulation with cell matrix h and the [W] law, no damping, no servo (the
// caller prescribes L).
Simulation periodicScene(const Mat3& h, double frictionDeg = 30.0) {
  Simulation sim = scenes::emptyScene(1.0, frictionDeg);
  sim.boundary = Boundary::Periodic;
  sim.cell.h = h;
  sim.cell.refresh();
  sim.cell.referenceLength = h.diagonal();
  sim.cell.prescribedGradient = true;
  return sim;
}

Mat3 sheared(double lx, double ly, double lz, double xy, double xz, double yz) {
  Mat3 h;
  h << lx, xy, xz, 0.0, ly, yz, 0.0, 0.0, lz;
  return h;
}

}  // namespace

// With no contacts, every particle is carried by the homogeneous flow: its scaled coordinates
// H^-1 x do not change, whatever L (stretch, shear and spin together).
TEST(PeriodicCell, AffineMotionWithoutContacts) {
  Simulation sim = periodicScene(sheared(0.1, 0.12, 0.09, 0.01, -0.02, 0.015));
  lab::Rng rng(3);
  std::vector<Vec3> scaled;
  for (int i = 0; i < 20; ++i) {
    const Vec3 s(rng.uniform(0.1, 0.9), rng.uniform(0.1, 0.9), rng.uniform(0.1, 0.9));
    scaled.push_back(s);
    sim.particles.addSphere(sim.cell.h * s, 1e-4, 2600.0);  // tiny: they never touch
  }
  sim.initialise();
  sim.dt = 1e-4;
  sim.cell.velocityGradient << 0.3, 0.2, -0.1, 0.05, -0.4, 0.25, -0.15, 0.1, 0.2;
  for (int i = 0; i < 2000; ++i) sim.step();  // 20 % of strain and more
  EXPECT_GT((sim.cell.h - sheared(0.1, 0.12, 0.09, 0.01, -0.02, 0.015)).norm(), 0.01);
  for (std::size_t i = 0; i < sim.particles.size(); ++i) {
    Vec3 s = sim.cell.hInverse * sim.particles.position[i];
    // A particle may have re-entered through a face: compare modulo whole periods.
    for (int a = 0; a < 3; ++a) s[a] -= std::floor(s[a] - scaled[i][a] + 0.5);
    EXPECT_LT((s - scaled[i]).norm(), 1e-12) << "particle " << i;
  }
  EXPECT_EQ(sim.touchingPairs(), 0u);
}

// A pair touching across a face of a sheared cell feels exactly the force of the same pair placed
// inside the cell, step after step, while it slides and rolls.
TEST(PeriodicCell, PairAcrossFaceEqualsPairInside) {
  const Mat3 h = sheared(0.02, 0.021, 0.022, 0.002, 0.003, -0.001);
  const double r = 1e-3, overlap = 2e-6;
  const Vec3 direction = Vec3(1.0, 0.3, -0.2).normalized();
  auto run = [&](const Vec3& centreA) {
    Simulation sim = periodicScene(h);
    sim.particles.addSphere(centreA, r, 2600.0);
    sim.particles.addSphere(centreA + (2 * r - overlap) * direction, r, 2600.0);
    sim.particles.velocity[1] = Vec3(0.0, 1e-3, 2e-3);
    sim.particles.angularVelocity[0] = Vec3(0.5, -1.0, 0.2);
    // Heavy bodies keep their prescribed motion (the contact would otherwise spring apart in a few
    // steps): this test is about geometry and kinematics, the balance tests use real masses.
    for (std::size_t i = 0; i < 2; ++i) sim.particles.setMass(i, 1e3, 1e-3);
    sim.initialise();
    sim.dt = 1e-7;
    std::vector<Vec3> forces;
    for (int i = 0; i < 300; ++i) {
      sim.step();
      forces.push_back(sim.particles.force[1]);
    }
    return forces;
  };
  // Inside: both centres well inside. Across: A just inside the upper x face, B's image beyond it.
  const std::vector<Vec3> inside = run(h * Vec3(0.4, 0.5, 0.5));
  const std::vector<Vec3> across = run(h * Vec3(0.99, 0.5, 0.5));
  for (std::size_t i = 0; i < inside.size(); ++i) {
    ASSERT_GT(inside[i].norm(), 0.0) << "step " << i;
    EXPECT_LE((inside[i] - across[i]).norm(), 1e-9 * inside[i].norm()) << "step " << i;
  }
}

// A loaded, sliding pair that drifts through a face: its contact and shear history survive the
// re-entry (the image shift changes, the force does not jump).
TEST(PeriodicCell, CrossingFaceKeepsContactAndHistory) {
  const Mat3 h = Mat3(Vec3(0.01, 0.01, 0.01).asDiagonal());
  const double r = 1e-3, overlap = 2e-6;
  auto run = [&](double start) {
    Simulation sim = periodicScene(h);
    sim.particles.addSphere(Vec3(start, 0.005, 0.005), r, 2600.0);
    sim.particles.addSphere(Vec3(start, 0.005, 0.005 + 2 * r - overlap), r, 2600.0);
    // Both drift along +x at 1 m/s; B also slides along y, so the shear spring loads.
    sim.particles.velocity[0] = Vec3(1.0, 0.0, 0.0);
    sim.particles.velocity[1] = Vec3(1.0, 1e-3, 0.0);
    for (std::size_t i = 0; i < 2; ++i) sim.particles.setMass(i, 1e3, 1e-3);  // keep the prescribed motion
    sim.initialise();
    sim.dt = 1e-7;
    std::vector<Vec3> forces;
    for (int i = 0; i < 40000; ++i) {  // 4 mm of drift: through the face at x = 0.01
      sim.step();
      forces.push_back(sim.particles.force[1]);
    }
    return std::make_pair(forces, sim);
  };
  auto [crossing, simCrossing] = run(0.0075);
  auto [staying, simStaying] = run(0.0005);
  // The first run's pair re-entered through the face (positions wrapped), the second did not.
  EXPECT_LT(simCrossing.particles.position[0].x(), 0.005);
  EXPECT_NE(simCrossing.particles.image[0][0], 0);
  EXPECT_EQ(simStaying.particles.image[0][0], 0);
  EXPECT_EQ(simCrossing.touchingPairs(), 1u);
  const Vec3 shear = simCrossing.contacts.sphereSphere.history.front().shearForce;
  EXPECT_GT(shear.norm(), 0.0);
  for (std::size_t i = 0; i < crossing.size(); ++i) {
    ASSERT_GT(staying[i].norm(), 0.0) << "step " << i;
    ASSERT_LE((crossing[i] - staying[i]).norm(), 1e-9 * staying[i].norm()) << "step " << i;
  }
}

// Undamped and unservoed, contact forces are pairwise equal and opposite, across faces too: the total
// momentum of the particles (fluctuating velocities) stays what it was, also while the cell deforms.
TEST(PeriodicCell, MomentumConservedUndamped) {
  Simulation sim = periodicScene(sheared(0.0072, 0.0072, 0.0072, 0.001, 0.0, 0.0));
  lab::Rng rng(11);
  // A dense random gas of 60 spheres (r 1 mm, solid fraction ~0.67, above random close packing) that overlaps itself and its images.
  for (int i = 0; i < 60; ++i) {
    const Vec3 s(rng.uniform(0, 1), rng.uniform(0, 1), rng.uniform(0, 1));
    sim.particles.addSphere(sim.cell.h * s, rng.uniform(0.9e-3, 1.1e-3), 2600.0);
    sim.particles.velocity.back() = Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)) * 1e-2;
    sim.particles.angularVelocity.back() = Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
  }
  sim.model.young = 1e7;  // soft: overlaps of a few % stay stable
  sim.initialise();
  sim.dt = 0.2 * sim.criticalTimeStep();
  sim.cell.velocityGradient << 0.0, 0.5, 0.0, 0.0, -0.2, 0.0, 0.0, 0.0, 0.1;
  auto momentum = [&] {
    Vec3 p = Vec3::Zero();
    for (std::size_t i = 0; i < sim.particles.size(); ++i) p += sim.particles.mass[i] * sim.particles.velocity[i];
    return p;
  };
  double scale = 0.0;
  for (std::size_t i = 0; i < sim.particles.size(); ++i) scale += sim.particles.mass[i] * sim.particles.velocity[i].norm();
  const Vec3 p0 = momentum();
  std::size_t crossFace = 0;
  for (int i = 0; i < 3000; ++i) {
    sim.step();
    ASSERT_LT((momentum() - p0).norm(), 1e-12 * scale) << "step " << i;
  }
  for (std::size_t c = 0; c < sim.contacts.sphereSphere.size(); ++c)
    crossFace += sim.contacts.sphereSphere.history[c].touching && sim.contacts.sphereSphere.shift[c] != ImageShift::kZero;
  EXPECT_GT(sim.touchingPairs(), 20u);
  EXPECT_GT(crossFace, 0u);
}

// A cell of about three diameters per side on a jammed simple cubic lattice: each sphere touches
// its six neighbours, through the faces too, once each (no image counted twice).
TEST(PeriodicCell, SmallCellCountsEveryImageOnce) {
  const double d = 2e-3;
  Simulation sim = periodicScene(Mat3(Vec3::Constant(3 * d).asDiagonal()));
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) sim.particles.addSphere(Vec3(i + 0.5, j + 0.5, k + 0.5) * d, 0.5 * d * 1.001, 2600.0);
  sim.initialise();
  sim.dt = 1e-8;
  sim.step();
  EXPECT_EQ(sim.touchingPairs(), 27u * 6u / 2u);
  for (int c : lab::contactsPerParticle(sim)) EXPECT_EQ(c, 6);
  // Isotropic lattice: the Love–Weber stress is spherical, sigma = (1/V) sum f d for 81 contacts.
  const double kn = sim.model.pairParams(0.5005 * d, 0.5005 * d).kn;
  const double f = kn * (1.001 * d - d);
  const double expected = 81.0 * f * d / (27.0 * d * d * d) / 3.0;
  EXPECT_NEAR(sim.cell.stress(0, 0), expected, 1e-9 * expected);
  EXPECT_NEAR(sim.cell.stress(2, 2), expected, 1e-9 * expected);
  EXPECT_NEAR(sim.cell.stress(0, 1), 0.0, 1e-9 * expected);
}

TEST(PeriodicCell, TooSmallCellIsRefused) {
  const double d = 2e-3;
  Simulation sim = periodicScene(Mat3(Vec3::Constant(2 * d).asDiagonal()));
  sim.particles.addSphere(Vec3::Constant(0.5 * d), 0.5 * d, 2600.0);
  sim.particles.addSphere(Vec3::Constant(1.5 * d), 0.5 * d, 2600.0);
  sim.initialise();
  sim.dt = 1e-8;
  try {
    sim.step();
    FAIL() << "a cell two diameters wide was accepted";
  } catch (const SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("periodic cell too small"), std::string::npos);
  }
}

namespace {

lab::RunConfig periodicConfig(int n, double pressure, double young) {
  lab::RunConfig c;
  c.sample.nParticles = n;
  c.sample.grading.type = "uniform";
  c.sample.grading.dMin = 4e-3;
  c.sample.grading.dMax = 6e-3;
  c.sample.prepFrictionDeg = 10.0;
  c.sample.prepRampSteps = 4000;
  c.test.boundary = "periodic";
  c.test.type = lab::TestType::Isotropic;
  c.test.confiningPressure = pressure;
  c.contact.young = young;
  return c;
}

}  // namespace

// The stress servo holds the imposed stress: at equilibrium the Love–Weber stress of the contacts,
// summed here independently of the engine's own sum, equals the target within the 1 % tolerance,
// from 10 kPa to 10 MPa and for soft and stiff grains, with the default settings.
class CellServo : public ::testing::TestWithParam<std::pair<double, double>> {};

TEST_P(CellServo, ReachesTargetStress) {
  const auto [pressure, young] = GetParam();
  lab::Laboratory lab(periodicConfig(200, pressure, young));
  lab.prepare();
  const Simulation& sim = lab.simulation();
  Mat3 s = Mat3::Zero();
  forEachTouchingContact(sim, [&](const ContactView& c) { s += c.force * c.branch.transpose(); });
  s /= sim.volume();
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(s(a, a) / pressure, 1.0, 0.011) << "axis " << a;
  // The shear stresses are servoed to zero too (symmetric parts).
  for (int k = 0; k < 3; ++k)
    EXPECT_LT(std::abs(0.5 * (s((k + 1) % 3, (k + 2) % 3) + s((k + 2) % 3, (k + 1) % 3))) / pressure, 0.011);
  EXPECT_LT(lab::unbalancedForceRatio(sim), 0.01);
}

INSTANTIATE_TEST_SUITE_P(PressureAndStiffness, CellServo,
                         ::testing::Values(std::make_pair(10e3, 3e9), std::make_pair(100e3, 30e9),
                                           std::make_pair(10e6, 70e9), std::make_pair(10e6, 3e9)));

// A rigid rotation of a loaded periodic sample (the cell spins with L = W, every grain with the same
// angular velocity): the stress turns with the body, R^T sigma R stays what it was.
TEST(PeriodicCell, RigidRotationLeavesBodyFrameStress) {
  lab::Laboratory lab(periodicConfig(150, 100e3, 30e9));
  lab.prepare();
  Simulation sim = lab.simulation();
  // A deviatoric state first: 0.3 % of axial compression at constant volume, then relaxation.
  sim.cell.prescribedGradient = true;
  sim.cell.velocityGradient = Vec3(0.5, 0.5, -1.0).asDiagonal();
  const long loading = std::lround(0.003 / sim.dt);
  for (long i = 0; i < loading; ++i) sim.step();
  sim.cell.velocityGradient.setZero();
  for (int i = 0; i < 3000; ++i) sim.step();
  const Mat3 s0 = sim.cell.stress;
  const double p = s0.trace() / 3.0;
  ASSERT_GT((s0(2, 2) - s0(0, 0)) / p, 0.1);  // a clearly deviatoric stress
  sim.localDamping = 0.0;
  for (auto& v : sim.particles.velocity) v.setZero();
  for (auto& omega : sim.particles.angularVelocity) omega.setZero();
  // The same sample left alone (no damping, no deformation) is the reference: it is not quite at
  // rest, and the rotated sample must evolve exactly like it, seen in the body frame.
  Simulation still = sim;
  const Vec3 axis = Vec3(0.3, -0.5, 0.8).normalized();
  const double rate = 200.0;  // rad/s
  Mat3 w;
  w << 0.0, -axis.z(), axis.y(), axis.z(), 0.0, -axis.x(), -axis.y(), axis.x(), 0.0;
  sim.cell.velocityGradient = rate * w;
  for (auto& omega : sim.particles.angularVelocity) omega += rate * axis;
  const long steps = std::lround(degToRad(30.0) / (rate * sim.dt));
  for (long i = 0; i < steps; ++i) {
    sim.step();
    still.step();
  }
  const Mat3 r = Eigen::AngleAxisd(rate * sim.dt * steps, axis).toRotationMatrix();
  const Mat3 body = r.transpose() * sim.cell.stress * r;
  // What remains (~1e-4 p here) is dynamics, not kinematics: the velocities the unbalanced forces
  // build up from rest are not carried round with the spin (the fluctuating velocity has no Coriolis
  // term), at 200 rad/s; a kinematic error (a stretch, an unrotated shear spring) gives 1e-2 and more.
  EXPECT_LT((body - still.cell.stress).norm() / p, 1e-3) << "still\n" << still.cell.stress << "\nbody frame\n" << body;
  // The cell turned as a rigid body, and in the lab frame the deviatoric stress clearly turned: the
  // check above is not trivial.
  EXPECT_LT((sim.cell.h - r * still.cell.h).norm() / still.cell.h.norm(), 1e-9);
  EXPECT_GT((sim.cell.stress - still.cell.stress).norm() / p, 0.05);
}

// The flexible membrane (core/membrane.hpp) against hand numbers: a ring of grains one per bin, the
// laboratory's membrane correction, holes, the shared shell, the volume servo; and a sample in the
// membrane at rest, whose contact network carries exactly the loads the membrane and platens put
// on it (the balance law), at the cell pressure.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "core/contact_view.hpp"
#include "core/membrane.hpp"
#include "lab/boundary_control.hpp"
#include "lab/measurements.hpp"
#include "lab/protocols.hpp"

using namespace grainlab;

namespace {

constexpr int kAround = 16, kAlong = 4;
constexpr double kRing = 0.02, kR = 0.002, kH = 0.04;

// One sphere at the centre of every bin, its centre kRing from the axis (0, 0).
Particles ring(double extraRadius = 0.0, int skipBin = -1) {
  Particles p;
  for (int k = 0; k < kAlong; ++k)
    for (int a = 0; a < kAround; ++a) {
      if (k * kAround + a == skipBin) continue;
      const double theta = -kPi + (a + 0.5) * 2.0 * kPi / kAround;
      const double rc = kRing + extraRadius;
      p.addSphere(Vec3(rc * std::cos(theta), rc * std::sin(theta), (k + 0.5) * kH / kAlong), kR, 2600.0);
    }
  return p;
}

Membrane flexible(double pressure) {
  Membrane m;
  m.rigid = false;
  m.around = kAround;
  m.along = kAlong;
  m.pressure = pressure;
  return m;
}

}  // namespace

// rho = kRing + r in every bin: the volume and area of that cylinder, and the pressure times the
// area shared out equally, radially inward.
TEST(Membrane, ARingOfGrainsCarriesThePressureTimesTheArea) {
  const Particles p = ring();
  Membrane m = flexible(100e3);
  m.measure(p, 0.0, kH);
  const double rho = kRing + kR;
  EXPECT_EQ(m.filledBins, kAround * kAlong);
  EXPECT_NEAR(m.volume / (kPi * rho * rho * kH), 1.0, 1e-12);
  EXPECT_NEAR(m.area / (2.0 * kPi * rho * kH), 1.0, 1e-12);
  EXPECT_NEAR(m.equivalentRadius() / rho, 1.0, 1e-12);
  m.applyPressure(p);
  ASSERT_EQ(m.grain.size(), static_cast<std::size_t>(kAround * kAlong));
  EXPECT_NEAR(m.radialForce / (100e3 * 2.0 * kPi * rho * kH), 1.0, 1e-12);
  EXPECT_NEAR(m.radialStress() / 100e3, 1.0, 1e-12);
  const double each = 100e3 * 2.0 * kPi * rho * kH / (kAround * kAlong);
  for (std::size_t k = 0; k < m.grain.size(); ++k) {
    const Vec3& x = p.position[m.grain[k]];
    const Vec3 inward = -Vec3(x[0], x[1], 0.0).normalized();
    EXPECT_NEAR(m.force[k].norm() / each, 1.0, 1e-12);
    EXPECT_NEAR(m.force[k].dot(inward) / each, 1.0, 1e-12);
  }
}

// A stretched sleeve adds its hoop tension: for a uniform bulge from D0 to D, the laboratory's
// radial membrane correction 2 E_m t eps_theta / D with eps_theta = (D - D0) / D0 (Kuerbis and Vaid
// 1990); a sleeve squeezed below D0 buckles and adds nothing.
TEST(Membrane, AStretchedSleeveAddsTheLaboratorysRadialMembraneCorrection) {
  const double young = 1.4e6, thickness = 0.3e-3;
  const Particles p = ring();
  const double d = 2.0 * (kRing + kR);
  for (double d0 : {d / 1.1, d / 1.02, d * 1.05}) {
    Membrane m = flexible(100e3);
    m.stiffness = young * thickness;
    m.referenceRadius = 0.5 * d0;
    m.measure(p, 0.0, kH);
    m.applyPressure(p);
    const double strain = (d - d0) / d0;
    const double correction = strain > 0.0 ? 2.0 * young * thickness * strain / d : 0.0;
    EXPECT_NEAR(m.radialStress() - 100e3, correction, 1e-9 * 100e3) << "D/D0 = " << d / d0;
    EXPECT_NEAR(m.hoopPressure, correction, 1e-9 * 100e3);
  }
}

// A bin with no grain carries nothing; its load goes to the others, so the total is unchanged.
TEST(Membrane, AHoleSharesItsLoadOutAndTheTotalStays) {
  const Particles p = ring(0.0, 5);
  Membrane m = flexible(50e3);
  m.measure(p, 0.0, kH);
  EXPECT_EQ(m.filledBins, kAround * kAlong - 1);
  const double rho = kRing + kR;
  EXPECT_NEAR(m.volume / (kPi * rho * rho * kH), 1.0, 1e-12);  // the hole at the mean radius
  m.applyPressure(p);
  EXPECT_EQ(m.grain.size(), static_cast<std::size_t>(kAround * kAlong - 1));
  EXPECT_NEAR(m.radialForce / (50e3 * m.area), 1.0, 1e-12);
  Vec3 sum = Vec3::Zero();
  for (const Vec3& f : m.force) sum += f;
  // The missing bin's opposite side is not balanced any more: the net force points away from the hole.
  EXPECT_GT(sum.norm(), 0.0);
}

// Two grains in one bin, the second half a shell deeper: weights 1 and 1/2 of the bin's load.
TEST(Membrane, GrainsWithinTheShellShareTheBinsLoadByDepth) {
  Particles p;
  const double theta = -kPi + 0.5 * 2.0 * kPi / kAround;
  const Vec3 dir(std::cos(theta), std::sin(theta), 0.0);
  p.addSphere(kRing * dir + Vec3(0, 0, 0.5 * kH / kAlong), kR, 2600.0);
  p.addSphere((kRing - 0.5e-3) * dir + Vec3(0, 0, 0.4 * kH / kAlong), kR, 2600.0);
  p.addSphere((kRing - 2.0e-3) * dir + Vec3(0, 0, 0.6 * kH / kAlong), kR, 2600.0);  // deeper than the shell
  Membrane m = flexible(100e3);
  m.shell = 1.0e-3;
  m.measure(p, 0.0, kH);
  m.applyPressure(p);
  ASSERT_EQ(m.grain.size(), 2u);
  EXPECT_EQ(m.grain[0], 0u);
  EXPECT_EQ(m.grain[1], 1u);
  EXPECT_NEAR(m.force[0].norm() / m.force[1].norm(), 2.0, 1e-12);
  EXPECT_NEAR((m.force[0].norm() + m.force[1].norm()) / m.radialForce, 1.0, 1e-12);
}

// Constant volume: the pressure is base + K eps, K = gain x modulus, and the base learns
// integral x K eps per step; never below zero.
TEST(Membrane, TheVolumeServoPressesASwollenSampleBack) {
  Particles p = ring();
  Membrane m = flexible(100e3);
  m.measure(p, 0.0, kH);
  m.control = MembraneControl::ConstantVolume;
  m.basePressure = 100e3;
  m.referenceVolume = m.volume / 1.01;
  m.volumeGain = 0.1;
  m.volumeIntegral = 0.01;
  const double eps = m.volume / m.referenceVolume - 1.0, k = 0.1 * 50e6;
  m.servo(50e6);
  EXPECT_NEAR(m.basePressure, 100e3 + 0.01 * k * eps, 1e-6);
  EXPECT_NEAR(m.pressure, 100e3 + 0.01 * k * eps + k * eps, 1e-6);
  m.servo(50e6);  // the same excess: the base learns again
  EXPECT_NEAR(m.pressure, 100e3 + 0.02 * k * eps + k * eps, 1e-6);
  m.referenceVolume = m.volume * 2.0;
  m.servo(50e6);
  EXPECT_EQ(m.pressure, 0.0);
}

namespace {

lab::RunConfig membraneConfig(double frictionDeg) {
  lab::RunConfig c;
  c.sample.nParticles = 800;
  c.sample.grading.type = "uniform";
  c.sample.grading.dMin = 4e-3;
  c.sample.grading.dMax = 6e-3;
  c.sample.prepFrictionDeg = frictionDeg;
  c.sample.seed = 3;
  c.contact.young = 3e9;
  c.contact.frictionDeg = frictionDeg;
  c.test.boundary = "membrane";
  c.test.type = lab::TestType::Isotropic;
  c.test.confiningPressure = 100e3;
  return c;
}

}  // namespace

// A frictional sample prepared in the rigid cylinder, then left in the flexible membrane: it stays
// at rest (a frictionless one would not: it flows under the surface grains' jostling), the membrane presses with the cell pressure, and the grains' contact network carries
// exactly what the membrane and the platens put on it: sum over contacts of f (x) branch equals
// sum over the external loads of F (x) x (the balance law of a body at rest).
TEST(Membrane, ASampleAtRestInTheMembraneCarriesItsLoads) {
  omp_set_num_threads(1);
  lab::Laboratory lab(membraneConfig(30.0));
  lab.prepare();
  Simulation& sim = lab.simulation();
  // Prepared in the rigid cylinder, brought to rest in the flexible membrane.
  ASSERT_FALSE(sim.membrane.rigid);
  EXPECT_LT(lab::unbalancedForceRatio(sim), 0.01);
  lab.boundary().beginTest();
  const double v0 = sim.volume();
  for (int i = 0; i < 3000; ++i) sim.step();
  EXPECT_LT(lab::unbalancedForceRatio(sim), 0.02);
  EXPECT_NEAR(sim.volume() / v0, 1.0, 0.005);
  EXPECT_NEAR((sim.membrane.radialStress() - sim.membrane.hoopPressure) / 100e3, 1.0, 1e-9);
  EXPECT_LT(sim.membrane.hoopPressure / 100e3, 0.01);
  EXPECT_NEAR(lab::boundaryStress(sim)[2] / 100e3, 1.0, 0.05);
  // Internal: grain-grain contacts, centre-to-centre branches. External: the membrane's forces and
  // the platens' at the grains' centres.
  Mat3 internal = Mat3::Zero(), external = Mat3::Zero();
  forEachTouchingContact(sim, [&](const ContactView& c) {
    if (c.wall) external += c.force * sim.particles.position[c.a].transpose();
    else internal += c.force * c.branch.transpose();
  });
  for (std::size_t k = 0; k < sim.membrane.grain.size(); ++k)
    external += sim.membrane.force[k] * sim.particles.position[sim.membrane.grain[k]].transpose();
  // The external loads' moment about the origin: -sum F x (compression positive, as internal).
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(internal(a, a) / -external(a, a), 1.0, 0.03) << "axis " << a;
}

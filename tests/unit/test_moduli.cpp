// Moduli as a laboratory reports them (lab/moduli.hpp): E and nu from an elastic increment, E50 on
// an analytic hyperbola, Eur on a synthetic loop, and the small-strain probe of a simple cubic
// lattice against its closed-form stiffness.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "lab/moduli.hpp"
#include "lab/protocols.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

// Hooke's law forwards (axisymmetric, compression positive), then the inverse must give E and nu
// back, also when the lateral stress was not held exactly.
TEST(Moduli, ElasticConstantsFromAnIncrement) {
  const double E = 180e6, nu = 0.22;
  for (const double ds3 : {0.0, 37.0, -120.0}) {
    const double ds1 = 2500.0;
    const double de1 = (ds1 - 2.0 * nu * ds3) / E;
    const double de3 = (ds3 - nu * (ds1 + ds3)) / E;
    const auto got = lab::elasticFromIncrement(ds1, ds3, de1, de3);
    ASSERT_TRUE(got.has_value());
    EXPECT_NEAR(got->young / E, 1.0, 1e-12);
    EXPECT_NEAR(got->poisson, nu, 1e-12);
  }
  // With the lateral stress held, nu is -d_eps3/d_eps1 by definition.
  const auto held = lab::elasticFromIncrement(1000.0, 0.0, 1e-5, -0.3e-5);
  ASSERT_TRUE(held.has_value());
  EXPECT_NEAR(held->young, 1000.0 / 1e-5, 1e-3);
  EXPECT_NEAR(held->poisson, 0.3, 1e-12);
  // No stress change: nothing to measure.
  EXPECT_FALSE(lab::elasticFromIncrement(0.0, 0.0, 1e-5, 0.0).has_value());
  // Extension for a compression increment: not an elastic modulus.
  EXPECT_FALSE(lab::elasticFromIncrement(1000.0, 0.0, -1e-5, 0.0).has_value());
  // Lateral contraction larger than the axial one (measured on a house of cards, e0 = 0.81, Z = 0.7:
  // nu = -1.2): not elastic; nor is nu = 0.6 (a dilating sample).
  EXPECT_FALSE(lab::elasticFromIncrement(289.8, -1.67, 1e-6, 1.21e-6).has_value());
  EXPECT_FALSE(lab::elasticFromIncrement(1000.0, 0.0, 1e-5, -0.6e-5).has_value());
  EXPECT_TRUE(lab::elasticFromIncrement(1000.0, 0.0, 1e-5, -0.49e-5).has_value());
}

// Kondner's hyperbola q = eps/(a + b eps) (Duncan & Chang 1970), sheared to eps_f: q_peak =
// eps_f/(a + b eps_f); q_peak/2 is reached at eps50 = (q_peak/2) a / (1 - b q_peak/2), so
// E50 = (q_peak/2)/eps50 = (1 - b q_peak/2)/a — 0.6 times the initial tangent 1/a here, so a
// tangent or a wrong half would fail.
TEST(Moduli, SecantE50OfAHyperbola) {
  const double a = 1.0 / 80e6, b = 1.0 / 400e3, epsF = 0.0273;
  std::vector<double> eps, q;
  for (int i = 0; i <= 2730; ++i) {
    eps.push_back(1e-5 * i);
    q.push_back(eps.back() / (a + b * eps.back()));
  }
  const double qPeak = epsF / (a + b * epsF);
  const double expected = (1.0 - b * qPeak / 2.0) / a;
  const auto e50 = lab::secantE50(eps, q);
  ASSERT_TRUE(e50.has_value());
  EXPECT_NEAR(*e50 / expected, 1.0, 1e-4);
  EXPECT_LT(expected / (1.0 / a), 0.7);
  // Starting from a consolidated deviator q0 (an anisotropic start), the secant is taken from it.
  std::vector<double> q2 = q;
  for (double& v : q2) v += 5e3;
  const double e50From = (0.5 * (qPeak + 5e3) - 5e3);
  const double eps50From = e50From * a / (1.0 - b * e50From);
  EXPECT_NEAR(*lab::secantE50(eps, q2) / (e50From / eps50From), 1.0, 1e-4);
  // A deviator that never rises: not measurable.
  EXPECT_FALSE(lab::secantE50({0.0, 0.01, 0.02}, {0.0, -1.0, -2.0}).has_value());
  EXPECT_FALSE(lab::secantE50({0.0}, {0.0}).has_value());
}

// A loop: loading to (eps_r, q_r), unloading along a line of slope Eu to q_r/2, reloading along
// q = q_t + Er x - c x^2 (x = eps - eps_t) up to eps_r. Eur is the secant of the reload branch,
// Er - c (eps_r - eps_t), which differs from the unloading slope and from the reload's tangent.
TEST(Moduli, UnloadReloadSecantOfASyntheticLoop) {
  const double epsR = 0.01, qR = 200e3, Eu = 400e6, Er = 300e6, c = 4e11;
  std::vector<double> eps, q;
  std::vector<int> phase;
  for (int i = 0; i <= 100; ++i) {  // loading (any shape)
    eps.push_back(epsR * i / 100.0);
    q.push_back(qR * std::sqrt(i / 100.0));
    phase.push_back(0);
  }
  phase.back() = 1;  // the reversal record opens the unloading branch
  const double epsT = epsR - 0.5 * qR / Eu, qT = 0.5 * qR;
  for (int i = 1; i <= 20; ++i) {
    eps.push_back(epsR - (epsR - epsT) * i / 20.0);
    q.push_back(qR - Eu * (epsR - eps.back()));
    phase.push_back(i == 20 ? 2 : 1);
  }
  const double span = epsR - epsT;
  for (int i = 1; i <= 20; ++i) {
    const double x = span * i / 20.0;
    eps.push_back(epsT + x);
    q.push_back(qT + Er * x - c * x * x);
    phase.push_back(i == 20 ? 0 : 2);
  }
  eps.push_back(epsR + 0.001);  // loading goes on
  q.push_back(qR + 1e3);
  phase.push_back(0);
  const auto loops = lab::unloadReloadLoops(eps, q, phase);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_DOUBLE_EQ(loops[0].eps1Reversal, epsR);
  EXPECT_NEAR(loops[0].qTurn, qT, 1e-6);
  ASSERT_TRUE(loops[0].eur.has_value());
  EXPECT_NEAR(*loops[0].eur / (Er - c * span), 1.0, 1e-9);
  // An unload that never turned: no Eur.
  const auto open = lab::unloadReloadLoops({0.0, 0.01, 0.009}, {0.0, 1.0, 0.5}, {0, 1, 1});
  ASSERT_EQ(open.size(), 1u);
  EXPECT_FALSE(open[0].eur.has_value());
  EXPECT_FALSE(open[0].restRelaxation.has_value());
  // A rest before the unload (phase 3, test.loop_rest): q at the first rest record is the loaded
  // deviator, the unload starts from the last (the relaxed one: 0.8 of it, relaxation 0.2), and Eur
  // is the secant from the turning point (0.45) to the reversal strain regained (0.7): 0.25/0.002.
  const auto rested = lab::unloadReloadLoops({0.0, 0.01, 0.01, 0.01, 0.009, 0.008, 0.009, 0.01},
                                             {0.0, 1.0, 0.9, 0.8, 0.6, 0.45, 0.6, 0.7}, {0, 3, 3, 1, 1, 2, 2, 0});
  ASSERT_EQ(rested.size(), 1u);
  EXPECT_DOUBLE_EQ(rested[0].qLoaded, 1.0);
  EXPECT_DOUBLE_EQ(rested[0].qReversal, 0.8);
  ASSERT_TRUE(rested[0].restRelaxation.has_value());
  EXPECT_NEAR(*rested[0].restRelaxation, 0.2, 1e-12);
  ASSERT_TRUE(rested[0].eur.has_value());
  EXPECT_NEAR(*rested[0].eur, 0.25 / 0.002, 1e-9);
}


// Simple cubic lattice of equal spheres, loaded isotropically, probed along a lattice axis (z).
// Every contact lies along x, y or z. An axial strain d_eps shortens each z contact by l d_eps
// (l = the centre spacing, d minus the overlap at p) and moves x and y neighbours only along z
// together, so their springs feel nothing: nu = 0. One z column carries F = kn (overlap) over the
// area l^2, so d_sigma_zz = kn l d_eps / l^2 and E = kn / l (= kn/d to the order of the overlap).
// Both hold up to terms of order p/E = p l/kn (the stress p carried through the change of the
// cell's volume), here with contacts stiff enough (kappa = kn/(p d) = 1e4) that these are 1e-4.
// A law with twice or half kn fails.
TEST(Moduli, ProbeOfASimpleCubicLatticeGivesKnOverSpacing) {
  const int n = 4;
  const lab::RunConfig config = scenes::simpleCubicLattice(n, 1e4);
  lab::Laboratory lab(config);
  lab.prepare();
  const Simulation before = lab.simulation();
  const lab::ModulusProbe probe = lab.probeModuli();
  ASSERT_TRUE(probe.settled) << probe.method;
  ASSERT_TRUE(probe.elastic.has_value()) << probe.method;
  const Vec3 l = lab.simulation().cell.h.diagonal() / n;
  const double expected = *config.contact.kn / l[2];
  EXPECT_NEAR(probe.elastic->young / expected, 1.0, 2e-3);
  EXPECT_NEAR(probe.elastic->poisson, 0.0, 2e-3);
  EXPECT_NEAR(probe.dEps1 / config.test.probeStrain, 1.0, 1e-3);
  // The probe leaves the sample exactly as it was.
  const Simulation& after = lab.simulation();
  ASSERT_EQ(after.particles.size(), before.particles.size());
  for (std::size_t i = 0; i < after.particles.size(); ++i)
    ASSERT_EQ(after.particles.position[i], before.particles.position[i]);
  EXPECT_EQ(after.stepCount, before.stepCount);
  EXPECT_EQ(after.cell.h, before.cell.h);
}

// With soft contacts ([O]'s kappa = 25) the order-p/E term is visible and has a closed form: at
// constant sigma_xx = F_x/(l_y l_z) a shorter l_z needs a smaller F_x, d F_x/F_x = -d_eps1, so each x
// contact opens by F_x d_eps1/kn and the lateral strain is -(F/(kn l)) d_eps1: an apparent
// nu = delta/l = p l/kn (delta = F/kn the overlap, F = p l^2). 4 % here, against 0 for the stiff case.
TEST(Moduli, ProbeOfASoftLatticeShowsTheInitialStressTerm) {
  const int n = 4;
  const lab::RunConfig config = scenes::simpleCubicLattice(n, 25.0);
  lab::Laboratory lab(config);
  lab.prepare();
  const lab::ModulusProbe probe = lab.probeModuli();
  ASSERT_TRUE(probe.elastic.has_value()) << probe.method;
  const double l = lab.simulation().cell.h(0, 0) / n;
  const double expectedNu = config.test.confiningPressure * l / *config.contact.kn;
  EXPECT_NEAR(probe.elastic->poisson / expectedNu, 1.0, 0.05);
}

// No probe asked for: nothing measured, and it says so.
TEST(Moduli, NoProbeIsNullNotZero) {
  lab::RunConfig config = scenes::simpleCubicLattice(4, 1e4);
  config.test.probeStrain = 0.0;
  lab::Laboratory lab(config);
  lab.prepare();
  const lab::ModulusProbe probe = lab.probeModuli();
  EXPECT_FALSE(probe.elastic.has_value());
  EXPECT_NE(probe.method.find("not measured"), std::string::npos);
}

// Macro-parameters (docs/laboratory.md §4) extracted from synthetic triaxial curves with known answers.
#include <gtest/gtest.h>

#include <cmath>

#include "core/types.hpp"
#include "lab/macro.hpp"

using namespace grainlab;

namespace {

// phi rises linearly to 40 deg at eps1 = 2 %, falls linearly to 32 deg at 8 %, then stays;
// eps_v contracts with slope 0.25 up to 1 %, dilates with slope -0.5 up to 10 %, then stays.
lab::TriaxialCurves syntheticCurves() {
  lab::TriaxialCurves c;
  const double s3 = 100e3;
  for (int i = 0; i <= 2000; ++i) {
    const double e = 1e-4 * i;
    double phi = e <= 0.02 ? 40.0 * e / 0.02 : (e <= 0.08 ? 40.0 - 8.0 * (e - 0.02) / 0.06 : 32.0);
    const double s = std::sin(degToRad(phi));
    c.eps1.push_back(e);
    c.sigma3.push_back(s3);
    c.sigma1.push_back(s3 * (1 + s) / (1 - s));
    const double ev = e <= 0.01 ? 0.25 * e : (e <= 0.10 ? 0.0025 - 0.5 * (e - 0.01) : 0.0025 - 0.045);
    c.epsV.push_back(ev);
    c.voidRatio.push_back(0.6 - 1.6 * ev);  // e = e0 - (1 + e0) eps_v
  }
  return c;
}

}  // namespace

TEST(Macro, FrictionAngleFromStresses) {
  EXPECT_NEAR(lab::mobilisedFrictionDeg(300e3, 100e3), 30.0, 1e-12);  // sin phi = 1/2
  EXPECT_NEAR(lab::dilatancyAngleDeg(-0.5), std::asin(0.5 / 2.5) * 180.0 / kPi, 1e-12);
  EXPECT_NEAR(lab::dilatancyAngleDeg(0.0), 0.0, 1e-12);
}

TEST(Macro, KnownAnswersFromSyntheticCurves) {
  const lab::MacroParameters m = lab::computeMacro(syntheticCurves());
  EXPECT_NEAR(m.phiPeakDeg, 40.0, 1e-9);
  EXPECT_NEAR(m.eps1AtPeak, 0.02, 1e-12);
  EXPECT_NEAR(m.phiResDeg, 32.0, 1e-9);          // window eps1 >= 16 %
  EXPECT_NEAR(m.residualFrom, 0.16, 1e-12);
  ASSERT_TRUE(m.psiMaxDeg.has_value());
  EXPECT_NEAR(*m.psiMaxDeg, radToDeg(std::asin(0.5 / 2.5)), 1e-6);
  EXPECT_GT(m.eps1AtPsiMax, 0.015);
  EXPECT_LT(m.eps1AtPsiMax, 0.095);
  // Critical state: q/p = 6 sin phi / (3 - sin phi) for triaxial compression.
  const double s = std::sin(degToRad(32.0));
  EXPECT_NEAR(m.residualStressRatio, 6 * s / (3 - s), 1e-9);
  EXPECT_NEAR(m.residualVoidRatio, 0.6 - 1.6 * (0.0025 - 0.045), 1e-9);
  // E50: secant to half the peak q. q_peak = s3 * 2 s/(1 - s) at 40 deg; half of it is reached where
  // 2 s/(1 - s) = q_peak/(2 s3), i.e. s = x/(2 + x), phi = asin(s), eps1 = 0.02 phi/40 deg.
  const double sp = std::sin(degToRad(40.0));
  const double half = 0.5 * 100e3 * 2 * sp / (1 - sp);
  const double x = half / 100e3;
  const double eps50 = 0.02 * radToDeg(std::asin(x / (2 + x))) / 40.0;
  ASSERT_TRUE(m.e50.has_value());
  EXPECT_NEAR(*m.e50 / (half / eps50), 1.0, 0.005);
}

// --- the critical-state criterion (lab::steadyState) and the two dilatancy conventions ------------

TEST(Macro, DilatancyAngleInBothConventionsAgainstHandNumbers) {
  // D = -d eps_v/d eps1 = 0.5: sin psi = D/(2 + D) = 0.2 -> 11.537 deg; tan psi = D -> 26.565 deg.
  EXPECT_NEAR(lab::dilatancyAngleDeg(-0.5), 11.536959032815489, 1e-9);
  EXPECT_NEAR(lab::dilatancyAngleTanDeg(-0.5), 26.565051177077990, 1e-9);
  EXPECT_NEAR(lab::dilatancyAngleTanDeg(0.25), -14.036243467926479, 1e-9);  // contraction: negative
  const lab::MacroParameters m = lab::computeMacro(syntheticCurves());
  ASSERT_TRUE(m.psiMaxTanDeg.has_value());
  EXPECT_NEAR(*m.psiMaxTanDeg, 26.565051177077990, 1e-6);  // the dilating branch's slope -0.5
}

TEST(Macro, CriticalStateReachedOnlyWhereStressRatioAndVolumeAreSteady) {
  // phi constant from 8 %, eps_v from 10 %: every 5 % window is steady once it starts after
  // 10 % (a window reaching back into the -0.5 branch has a volumetric slope above 0.02 as soon as
  // it holds more than ~2 records of it), so eps* is just below 15 %.
  const lab::MacroParameters m = lab::computeMacro(syntheticCurves());
  const lab::SteadyState& cs = m.steady;
  ASSERT_TRUE(cs.evaluated);
  ASSERT_TRUE(cs.reached);
  EXPECT_GT(cs.reachedAt, 0.14);
  EXPECT_LE(cs.reachedAt, 0.15 + 1e-12);
  const double s = std::sin(degToRad(32.0));
  EXPECT_NEAR(cs.stressRatio, 6 * s / (3 - s), 1e-9);
  EXPECT_NEAR(cs.voidRatio, 0.6 - 1.6 * (0.0025 - 0.045), 1e-9);
  EXPECT_NEAR(cs.meanStress, 100e3 * (1 + 2 * s / (1 - s) / 3), 1e-3);  // p = s3 + q/3
  EXPECT_NEAR(cs.endVolumetricRate, 0.0, 1e-12);
}

TEST(Macro, ASampleStillDilatingHasNoCriticalState) {
  // A dense sample at 20 %: phi already constant, but eps_v still falling at -0.3 to the end.
  lab::TriaxialCurves c = syntheticCurves();
  for (std::size_t i = 0; i < c.eps1.size(); ++i) {
    const double e = c.eps1[i];
    if (e > 0.10) {
      c.epsV[i] = 0.0025 - 0.045 - 0.3 * (e - 0.10);
      c.voidRatio[i] = 0.6 - 1.6 * c.epsV[i];
    }
  }
  const lab::SteadyState cs = lab::computeMacro(c).steady;
  ASSERT_TRUE(cs.evaluated);
  EXPECT_FALSE(cs.reached);
  EXPECT_NEAR(cs.endVolumetricRate, -0.3, 1e-9);
  EXPECT_NEAR(cs.endVoidRatioRate, 0.48, 1e-9);  // de = -(1 + e0) d eps_v
  EXPECT_NEAR(cs.endStressRatioRate, 0.0, 1e-9);
}

TEST(Macro, AStressRatioStillFallingHasNoCriticalState) {
  // Volume steady, but q/p softening at 1 per unit strain (above the 0.5 threshold) to the end.
  std::vector<double> eps, eta, ev, e, p;
  for (int i = 0; i <= 400; ++i) {
    eps.push_back(5e-4 * i);
    eta.push_back(1.4 - 1.0 * eps.back());
    ev.push_back(-0.03);
    e.push_back(0.65);
    p.push_back(100e3);
  }
  lab::SteadyState cs = lab::steadyState(eps, eta, ev, e, p);
  ASSERT_TRUE(cs.evaluated);
  EXPECT_FALSE(cs.reached);
  EXPECT_NEAR(cs.endStressRatioRate, -1.0, 1e-9);
  // The same curve softening at 0.4 per unit strain is within the criterion.
  for (std::size_t i = 0; i < eps.size(); ++i) eta[i] = 1.4 - 0.4 * eps[i];
  cs = lab::steadyState(eps, eta, ev, e, p);
  EXPECT_TRUE(cs.reached);
  EXPECT_NEAR(cs.reachedAt, 0.05, 1e-12);  // from the first full window on
}

TEST(Macro, NoisySteadyCurvesReachItAndShortTestsAreNotEvaluated) {
  // Flat curves with record-to-record noise (+-0.01 in q/p, +-1e-4 in eps_v), as DEM gives.
  std::vector<double> eps, eta, ev, e, p;
  std::uint32_t state = 12345;
  auto noise = [&] {
    state = state * 1664525u + 1013904223u;
    return static_cast<double>(state >> 8) / static_cast<double>(1u << 24) - 0.5;
  };
  for (int i = 0; i <= 300; ++i) {
    eps.push_back(1e-3 * i);
    eta.push_back(1.2 + 0.02 * noise());
    ev.push_back(-0.05 + 2e-4 * noise());
    e.push_back(0.68 - 1.6 * (ev.back() + 0.05));
    p.push_back(100e3 * (1 + 0.01 * noise()));
  }
  const lab::SteadyState cs = lab::steadyState(eps, eta, ev, e, p);
  EXPECT_TRUE(cs.reached);
  EXPECT_NEAR(cs.stressRatio, 1.2, 0.005);
  // A test shorter than one window: not evaluated, no critical state and no end values.
  const std::vector<double> shortEps(eps.begin(), eps.begin() + 40);
  const std::vector<double> shortEta(eta.begin(), eta.begin() + 40), shortEv(ev.begin(), ev.begin() + 40),
      shortE(e.begin(), e.begin() + 40), shortP(p.begin(), p.begin() + 40);
  const lab::SteadyState none = lab::steadyState(shortEps, shortEta, shortEv, shortE, shortP);
  EXPECT_FALSE(none.evaluated);
  EXPECT_FALSE(none.reached);
}

TEST(Macro, TheAutoWindowIsAQuarterOfTheTestAtLeast5Percent) {
  EXPECT_DOUBLE_EQ(lab::autoCsWindow(0.20), 0.05);  // the 20 % triaxial tests keep the 0.05 window
  EXPECT_DOUBLE_EQ(lab::autoCsWindow(0.15), 0.05);
  EXPECT_DOUBLE_EQ(lab::autoCsWindow(2.0), 0.5);
  EXPECT_DOUBLE_EQ(lab::autoCsWindow(0.5), 0.125);
}

// Simple shear to gamma = 2 of a small sample: tau/sigma_n fluctuates by +-0.1 over gamma ~ 0.07
// (stick-slip of force chains) about a flat mean. A 0.05 window sees the fluctuation's slope
// (up to 0.1 * 2 pi / 0.07 ~ 9), not a trend; the auto window of a quarter of the test averages it.
// A sample whose void ratio still rises by 0.1 per unit gamma under the same noise is refused by
// either window.
TEST(Macro, FluctuatingSteadyShearNeedsTheLongWindowAndAStillDilatingOneFailsBoth) {
  std::vector<double> g, eta, ev, e, p, eRising, evRising;
  for (int i = 0; i <= 2000; ++i) {
    const double x = 1e-3 * i;
    const double wobble = 0.1 * std::sin(2 * kPi * x / 0.07) + 0.03 * std::sin(2 * kPi * x / 0.023 + 1.0);
    g.push_back(x);
    eta.push_back(x < 0.3 ? 0.65 + 0.5 * (0.3 - x) : 0.65 + wobble);
    ev.push_back(x < 0.3 ? -0.1 * x : -0.03 + 0.002 * std::sin(2 * kPi * x / 0.11));
    e.push_back(0.60 - 1.6 * ev.back());
    evRising.push_back(-0.1 * x + 0.002 * std::sin(2 * kPi * x / 0.11));
    eRising.push_back(0.60 - 1.6 * evRising.back());
    p.push_back(200e3);
  }
  lab::MacroSettings shortWindow;
  EXPECT_FALSE(lab::steadyState(g, eta, ev, e, p, shortWindow).reached);
  lab::MacroSettings autoWindow;
  autoWindow.csWindow = lab::autoCsWindow(2.0);
  const lab::SteadyState cs = lab::steadyState(g, eta, ev, e, p, autoWindow);
  ASSERT_TRUE(cs.reached);
  EXPECT_NEAR(cs.stressRatio, 0.65, 0.01);
  EXPECT_NEAR(cs.voidRatio, 0.60 + 1.6 * 0.03, 0.002);
  EXPECT_LT(cs.reachedAt, 1.0);
  EXPECT_FALSE(lab::steadyState(g, eta, evRising, eRising, p, autoWindow).reached);
  EXPECT_FALSE(lab::steadyState(g, eta, evRising, eRising, p, shortWindow).reached);
}

TEST(Macro, StressDilatancyDataAgainstTheSyntheticCurves) {
  // eps_v = 0.0025 - 0.5 (eps1 - 0.01) on 1 % < eps1 < 10 %: D = 0.5 wherever the +-0.5 % window
  // lies inside that branch; R = sigma1/sigma3 and q/p from the stresses of each record.
  const lab::TriaxialCurves c = syntheticCurves();
  const lab::StressDilatancy sd = lab::stressDilatancy(c, false);
  ASSERT_EQ(sd.strain.size(), c.eps1.size());  // every record has a window of >= 3 records
  ASSERT_EQ(sd.principalRatio.size(), sd.strain.size());
  int checked = 0;
  for (std::size_t i = 0; i < sd.strain.size(); ++i) {
    const double e = sd.strain[i];
    const double s1 = c.sigma1[i], s3 = c.sigma3[i];
    EXPECT_NEAR(sd.principalRatio[i], s1 / s3, 1e-12);
    EXPECT_NEAR(sd.stressRatio[i], (s1 - s3) / ((s1 + 2 * s3) / 3), 1e-12);
    if (e > 0.0151 && e < 0.0949) {
      EXPECT_NEAR(sd.dilatancy[i], 0.5, 1e-9) << "eps1 = " << e;
      ++checked;
    }
    if (e > 0.1051) EXPECT_NEAR(sd.dilatancy[i], 0.0, 1e-9);
    if (e < 0.0049) EXPECT_NEAR(sd.dilatancy[i], -0.25, 1e-9);  // contraction: D < 0
  }
  EXPECT_GT(checked, 700);
}

// Macro-parameters (PHYSICS.md §7.3) extracted from synthetic triaxial curves with known answers.
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
  EXPECT_NEAR(m.csStressRatio, 6 * s / (3 - s), 1e-9);
  EXPECT_NEAR(m.csVoidRatio, 0.6 - 1.6 * (0.0025 - 0.045), 1e-9);
  // E50: secant to half the peak q. q_peak = s3 * 2 s/(1 - s) at 40 deg; half of it is reached where
  // 2 s/(1 - s) = q_peak/(2 s3), i.e. s = x/(2 + x), phi = asin(s), eps1 = 0.02 phi/40 deg.
  const double sp = std::sin(degToRad(40.0));
  const double half = 0.5 * 100e3 * 2 * sp / (1 - sp);
  const double x = half / 100e3;
  const double eps50 = 0.02 * radToDeg(std::asin(x / (2 + x))) / 40.0;
  ASSERT_TRUE(m.e50.has_value());
  EXPECT_NEAR(*m.e50 / (half / eps50), 1.0, 0.005);
}

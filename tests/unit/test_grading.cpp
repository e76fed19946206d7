// The grading sampler (src/lab/grading.*, docs/laboratory.md §1) against the curves it samples: 1e5 draws
// of a sieve curve have the curve's d10, d30, d50, d60 by mass and its mass fraction in every sieve
// interval; a range uniform by number has the moments of the uniform distribution.
//
// Tolerances are statistical, computed from the draws: a quantile by mass of n draws weighted by
// d^3 has the standard error sqrt(p (1 - p) / n_eff) / f(d_p), with f the curve's mass density
// (dP/dd, per metre) at d_p and n_eff = (sum d^3)^2 / sum d^6 the effective number of equally
// weighted draws (Kish); the tests allow 4 standard errors (a fixed seed makes them deterministic).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "lab/grading.hpp"

using namespace grainlab;

namespace {

struct Curve {
  std::vector<double> d;  // [m]
  std::vector<double> p;  // [%] passing by mass
  // Diameter at percent passing q, by linear interpolation of the curve (its definition).
  double diameterAt(double q) const {
    for (std::size_t k = 0; k + 1 < d.size(); ++k)
      if (q <= p[k + 1] && p[k + 1] > p[k]) return d[k] + (q - p[k]) / (p[k + 1] - p[k]) * (d[k + 1] - d[k]);
    return d.back();
  }
  // Mass density of the curve at d_q, as a fraction per metre.
  double densityAt(double q) const {
    for (std::size_t k = 0; k + 1 < d.size(); ++k)
      if (q <= p[k + 1] && p[k + 1] > p[k]) return (p[k + 1] - p[k]) / 100.0 / (d[k + 1] - d[k]);
    return 0.0;
  }
};

double effectiveCount(const std::vector<double>& draws) {
  double s3 = 0.0, s6 = 0.0;
  for (double x : draws) {
    s3 += x * x * x;
    s6 += x * x * x * x * x * x;
  }
  return s3 * s3 / s6;
}

void checkCurve(const Curve& curve, std::uint64_t seed) {
  lab::GradingConfig g;
  g.type = "curve";
  g.diameters = curve.d;
  g.passing = curve.p;
  lab::Rng rng(seed);
  const int n = 100000;
  const std::vector<double> draws = lab::sampleDiameters(g, n, rng);
  ASSERT_EQ(draws.size(), static_cast<std::size_t>(n));
  const double nEff = effectiveCount(draws);
  const lab::GradingStats s = lab::gradingStats(draws);
  const std::pair<double, double> quantiles[] = {{10, s.d10}, {30, s.d30}, {50, s.d50}, {60, s.d60}};
  for (const auto& [q, measured] : quantiles) {
    const double standardError = std::sqrt(q / 100 * (1 - q / 100) / nEff) / curve.densityAt(q);
    EXPECT_NEAR(measured, curve.diameterAt(q), 4.0 * standardError) << "d" << q;
  }
  EXPECT_NEAR(s.cu, curve.diameterAt(60) / curve.diameterAt(10), 0.01 * s.cu);
  // Mass fraction in each sieve interval = the step of the curve there (none in a flat step).
  double total = 0.0;
  for (double x : draws) total += x * x * x;
  for (std::size_t k = 0; k + 1 < curve.d.size(); ++k) {
    double inside = 0.0;
    for (double x : draws)
      if (x >= curve.d[k] && x < curve.d[k + 1]) inside += x * x * x;
    const double expected = (curve.p[k + 1] - curve.p[k]) / 100.0;
    // Binomial error of a weighted fraction, with the effective count.
    EXPECT_NEAR(inside / total, expected, 4.0 * std::sqrt(expected * (1 - expected) / nEff) + 1e-12)
        << "interval " << k;
  }
  EXPECT_GE(*std::min_element(draws.begin(), draws.end()), curve.d.front());
  EXPECT_LE(*std::max_element(draws.begin(), draws.end()), curve.d.back());
}

}  // namespace

// Straight line 2–8 mm, 0–100 %: d_q = 2 mm + q/100 x 6 mm, so d10 = 2.6, d30 = 3.8, d50 = 5.0,
// d60 = 5.6 mm and Cu = 2.154. (Uniform by number on 2–8 mm would give d50 by mass = 6.73 mm.)
TEST(GradingSampler, StraightCurveQuantilesByMass) {
  const Curve c{{2e-3, 8e-3}, {0, 100}};
  EXPECT_DOUBLE_EQ(c.diameterAt(50), 5e-3);
  checkCurve(c, 11);
}

// 1–2–4–8 mm at 0–20–70–100 %: d10 = 1.5, d30 = 2.4, d50 = 3.2, d60 = 3.6 mm.
TEST(GradingSampler, MultiPointCurveQuantilesByMass) {
  const Curve c{{1e-3, 2e-3, 4e-3, 8e-3}, {0, 20, 70, 100}};
  EXPECT_NEAR(c.diameterAt(10), 1.5e-3, 1e-15);
  EXPECT_NEAR(c.diameterAt(30), 2.4e-3, 1e-15);
  EXPECT_NEAR(c.diameterAt(50), 3.2e-3, 1e-15);
  EXPECT_NEAR(c.diameterAt(60), 3.6e-3, 1e-15);
  checkCurve(c, 12);
}

// Gap-graded (nothing between 2 and 4 mm): d10 = 1.5 mm, d30 = 4 + 10/80 x 4 = 4.5 mm,
// d50 = 5.5 mm, d60 = 6.0 mm.
TEST(GradingSampler, GapGradedCurve) {
  const Curve c{{1e-3, 2e-3, 4e-3, 8e-3}, {0, 20, 20, 100}};
  EXPECT_NEAR(c.diameterAt(30), 4.5e-3, 1e-15);
  checkCurve(c, 13);
}

// Uniform by number on [a, b]: mean (a + b)/2, variance (b - a)^2/12; by mass the passing curve is
// (d^4 - a^4)/(b^4 - a^4), so d50 = ((a^4 + b^4)/2)^(1/4).
TEST(GradingSampler, UniformByNumberMoments) {
  lab::GradingConfig g;
  g.type = "uniform";
  g.dMin = 4e-3;
  g.dMax = 6e-3;
  lab::Rng rng(5);
  const int n = 100000;
  const std::vector<double> draws = lab::sampleDiameters(g, n, rng);
  double mean = 0.0;
  for (double x : draws) mean += x;
  mean /= n;
  double var = 0.0;
  for (double x : draws) var += (x - mean) * (x - mean);
  var /= n - 1;
  const double a = 4e-3, b = 6e-3, sigma2 = (b - a) * (b - a) / 12.0;
  EXPECT_NEAR(mean, 0.5 * (a + b), 4.0 * std::sqrt(sigma2 / n));
  // The variance of the sample variance of a uniform law is (mu4 - sigma^4)/n, mu4 = 9/5 sigma^4.
  EXPECT_NEAR(var, sigma2, 4.0 * std::sqrt(0.8 * sigma2 * sigma2 / n));
  const double d50 = std::pow(0.5 * (std::pow(a, 4) + std::pow(b, 4)), 0.25);  // 5.2004 mm
  const double massDensity = 4.0 * std::pow(d50, 3) / (std::pow(b, 4) - std::pow(a, 4));
  const lab::GradingStats s = lab::gradingStats(draws);
  EXPECT_NEAR(s.d50, d50, 4.0 * std::sqrt(0.25 / effectiveCount(draws)) / massDensity);
  EXPECT_GE(s.dMin, a);
  EXPECT_LT(s.dMax, b);
}

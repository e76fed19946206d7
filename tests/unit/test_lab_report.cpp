// The macro-values of the undrained and oedometer tests (lab/test_report.hpp) against hand numbers.
#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.hpp"
#include "lab/run_report.hpp"
#include "lab/test_report.hpp"

using namespace grainlab;

namespace {
lab::Record rec(double eps1, double p, double q, double u) {
  lab::Record r;
  r.eps1 = eps1;
  r.p = p;
  r.q = q;
  r.u = u;
  return r;
}
}  // namespace

// A loose sample's path: p' falls from 100 to 20 kPa, then rises; the phase transformation is the
// minimum of p' (q = 30 kPa at eps1 = 2 %), u_max the largest u; liquefied only below (1 - ru) p0.
TEST(LabReport, UndrainedPhaseTransformationAndLiquefaction) {
  const std::vector<lab::Record> r{rec(0, 100e3, 0, 0), rec(0.01, 60e3, 50e3, 57e3), rec(0.02, 20e3, 30e3, 90e3),
                                   rec(0.03, 40e3, 60e3, 80e3)};
  const lab::UndrainedSummary s = lab::undrainedSummary(r, 100e3, 0.95, 3e-15);
  EXPECT_EQ(s.uMax, 90e3);
  EXPECT_EQ(s.pMin, 20e3);
  ASSERT_TRUE(s.qAtPhaseTransformation);
  EXPECT_EQ(*s.qAtPhaseTransformation, 30e3);
  EXPECT_EQ(*s.eps1AtPhaseTransformation, 0.02);
  EXPECT_FALSE(s.liquefied);  // 20 kPa > 5 kPa
  EXPECT_EQ(s.volumeDriftMax, 3e-15);
  EXPECT_TRUE(lab::undrainedSummary(r, 100e3, 0.75, 0.0).liquefied);  // 20 kPa <= (1 - 0.75) 100 kPa
}

// A dense sample whose p' only rises has no phase transformation (null, not the first record).
TEST(LabReport, UndrainedDilativePathHasNoPhaseTransformation) {
  const std::vector<lab::Record> r{rec(0, 100e3, 0, 0), rec(0.01, 150e3, 200e3, -20e3), rec(0.02, 300e3, 500e3, -80e3)};
  const lab::UndrainedSummary s = lab::undrainedSummary(r, 100e3, 0.95, 0.0);
  EXPECT_FALSE(s.qAtPhaseTransformation);
  EXPECT_EQ(s.uMax, 0.0);
}

// An oedometer curve built from Cc = 0.05, Cs = 0.01 and K0 = 0.45 on loading: the summary recovers
// them; K0 averages only the normally loaded part (sigma_v >= sqrt(p0 sigma_v,max)).
TEST(LabReport, OedometerIndicesFromTheCurve) {
  std::vector<lab::Record> r;
  const double p0 = 100e3, smax = 1e6, e0 = 0.7;
  for (int i = 0; i <= 20; ++i) {
    lab::Record x;
    x.sigma1 = p0 * std::pow(10.0, i / 20.0);
    x.e = e0 - 0.05 * std::log10(x.sigma1 / p0);
    const double k = x.sigma1 >= std::sqrt(p0 * smax) ? 0.45 : 1.0 - 0.55 * std::log10(x.sigma1 / p0) * 2.0;
    x.sigma2 = x.sigma3 = k * x.sigma1;
    x.loadDirection = 1;
    r.push_back(x);
  }
  const double eMax = r.back().e;
  for (int i = 1; i <= 10; ++i) {
    lab::Record x;
    x.sigma1 = smax * std::pow(10.0, -i / 10.0 * 0.7);
    x.e = eMax + 0.01 * std::log10(smax / x.sigma1);
    x.sigma2 = x.sigma3 = 0.8 * x.sigma1;
    x.loadDirection = -1;
    r.push_back(x);
  }
  const lab::OedometerSummary s = lab::oedometerSummary(r, p0);
  ASSERT_TRUE(s.cc && s.cs && s.k0 && s.k0Unloading);
  EXPECT_NEAR(*s.cc, 0.05, 1e-12);
  EXPECT_NEAR(*s.cs, 0.01, 1e-12);
  EXPECT_NEAR(*s.k0, 0.45, 1e-12);
  EXPECT_NEAR(*s.k0Unloading, 0.8, 1e-12);
  EXPECT_EQ(s.sigmaVMax, smax);
  EXPECT_EQ(s.loadingRecords, 11u);
}

// Nothing to measure: no loading above p0 gives nulls, not zeros.
TEST(LabReport, OedometerWithoutLoadingIsNull) {
  lab::Record x;
  x.sigma1 = 100e3;
  const lab::OedometerSummary s = lab::oedometerSummary({x, x}, 100e3);
  EXPECT_FALSE(s.cc);
  EXPECT_FALSE(s.k0);
}

// The run report (lab/run_report.hpp): summary keys from the probe and the records.

// A probe that measured nu0 outside [0, 1/2] did not measure an elastic Poisson ratio: nu0 (and its
// alias nu) is null, the measured number is kept beside it, and a warning says so.
TEST(RunReport, ProbeNullsAPoissonRatioOutsideTheElasticRange) {
  lab::ModulusProbe probe;
  probe.elastic = lab::ElasticConstants{50e6, -0.2};
  probe.method = "hand";
  lab::Json s;
  lab::reportProbe(probe, s);
  EXPECT_DOUBLE_EQ(s["E0_MPa"].get<double>(), 50.0);
  EXPECT_DOUBLE_EQ(s["E_MPa"].get<double>(), 50.0);
  EXPECT_TRUE(s["nu0"].is_null());
  EXPECT_TRUE(s["nu"].is_null());
  EXPECT_DOUBLE_EQ(s["nu0_measured"].get<double>(), -0.2);
  ASSERT_EQ(s["warnings"].size(), 1u);
  EXPECT_NE(s["warnings"][0].get<std::string>().find("-0.200"), std::string::npos);
  EXPECT_EQ(s["E0_method"], "hand");
}

// A non-positive E0 is null with E0_MPa_measured; a probe that measured nothing gives nulls and no
// warning; a non-finite modulus is refused, never written.
TEST(RunReport, ProbeNullsANonPositiveModulusAndRefusesNaN) {
  lab::ModulusProbe probe;
  probe.elastic = lab::ElasticConstants{-3e6, 0.25};
  lab::Json s;
  lab::reportProbe(probe, s);
  EXPECT_TRUE(s["E0_MPa"].is_null());
  EXPECT_DOUBLE_EQ(s["E0_MPa_measured"].get<double>(), -3.0);
  EXPECT_DOUBLE_EQ(s["nu0"].get<double>(), 0.25);

  lab::Json none;
  lab::reportProbe(lab::ModulusProbe{}, none);
  EXPECT_TRUE(none["E0_MPa"].is_null());
  EXPECT_TRUE(none["nu0"].is_null());
  EXPECT_FALSE(none.contains("warnings"));

  probe.elastic = lab::ElasticConstants{std::nan(""), 0.25};
  lab::Json bad;
  EXPECT_THROW(lab::reportProbe(probe, bad), SimulationError);
}

// A record's micromechanics by column name: a value that could not be measured is null, not 0.
TEST(RunReport, MicroColumnsNullWhereNotMeasured) {
  lab::Record r;
  r.eps1 = 0.03;
  r.micro = {1.5, std::nan("")};
  r.energyResidual = std::nan("");
  const lab::Json j = lab::microJson(r, {"Z", "a_r"});
  EXPECT_DOUBLE_EQ(j["Z"].get<double>(), 1.5);
  EXPECT_TRUE(j["a_r"].is_null());
  EXPECT_TRUE(j["energy_residual"].is_null());
  EXPECT_DOUBLE_EQ(j["eps1"].get<double>(), 0.03);
}

// The band's onset is where it appears for good: a band seen at one window and lost at the next
// does not count; none in the last window is no onset. Records between windows (band not looked
// for, bandMeasured 0) neither end nor start a band.
TEST(RunReport, BandOnsetIsWhereTheBandStaysToTheEnd) {
  const double none = std::nan("");
  const double between = -1.0;  // a record between two window ends
  auto records = [&](std::vector<double> inclination) {
    std::vector<lab::Record> r(inclination.size());
    for (std::size_t i = 0; i < r.size(); ++i) {
      r[i].eps1 = 0.01 * static_cast<double>(i);
      r[i].bandMeasured = inclination[i] == between ? 0.0 : 1.0;
      r[i].bandInclinationDeg = inclination[i] == between ? none : inclination[i];
    }
    return r;
  };
  const auto onset = lab::bandOnset(records({none, 55.0, none, 58.0, 60.0}));
  ASSERT_TRUE(onset);
  EXPECT_DOUBLE_EQ(*onset, 0.03);
  const auto sparse = lab::bandOnset(records({none, between, 55.0, between, between, 58.0, between}));
  ASSERT_TRUE(sparse);
  EXPECT_DOUBLE_EQ(*sparse, 0.02);
  EXPECT_FALSE(lab::bandOnset(records({none, 55.0, between, none, between})));
  EXPECT_FALSE(lab::bandOnset(records({between, between})));
  EXPECT_FALSE(lab::bandOnset({}));
}

// summary.json's shear_band from a band in a wall box of a simple cubic packing: the numbers of the
// band and the void ratio 6/pi - 1 on both sides; null without a band.
TEST(RunReport, ShearBandKeys) {
  Simulation sim;
  for (int x = 0; x < 12; ++x)
    for (int y = 0; y < 12; ++y)
      for (int z = 0; z < 24; ++z) sim.particles.addSphere(Vec3(x + 0.5, y + 0.5, z + 0.5) * 1e-3, 0.5e-3, 2650.0);
  sim.box.setBounds(Vec3::Zero(), Vec3(12, 12, 24) * 1e-3);
  lab::ShearBand b;
  b.normal = Vec3(std::sin(M_PI / 3), 0.0, std::cos(M_PI / 3));
  b.centre = Vec3(6, 6, 12) * 1e-3;
  b.inclinationDeg = 60.0;
  b.thickness = 6e-3;
  b.grains = 900;
  const lab::Json j = lab::shearBandJson(b, true, sim, 1e-3, 0.04, 0.05);
  EXPECT_TRUE(j["detected"].get<bool>());
  EXPECT_DOUBLE_EQ(j["onset_eps1"].get<double>(), 0.04);
  EXPECT_DOUBLE_EQ(j["onset_over_peak"].get<double>(), 0.8);
  EXPECT_DOUBLE_EQ(j["inclination_deg"].get<double>(), 60.0);
  EXPECT_DOUBLE_EQ(j["thickness_d50"].get<double>(), 6.0);
  EXPECT_EQ(j["grains"].get<int>(), 900);
  EXPECT_NEAR(j["void_ratio_inside"].get<double>(), 6.0 / M_PI - 1.0, 0.03);
  EXPECT_NEAR(j["void_ratio_outside"].get<double>(), 6.0 / M_PI - 1.0, 0.02);
  // Looked for and not found: detected false; not looked for: null. Every other value null.
  const lab::Json none = lab::shearBandJson(std::nullopt, true, sim, 1e-3, std::nullopt, 0.05);
  EXPECT_FALSE(none["detected"].get<bool>());
  EXPECT_EQ(none.size(), j.size());
  for (const auto& [key, value] : none.items())
    if (key != "detected") EXPECT_TRUE(value.is_null()) << key;
  EXPECT_TRUE(lab::shearBandJson(std::nullopt, false, sim, 1e-3, std::nullopt, 0.05)["detected"].is_null());
}

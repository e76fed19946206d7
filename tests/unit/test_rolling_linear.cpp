// The linear rolling-resistance law of [R] (docs/physics.md §4.2), the per-grain rolling friction from
// sphericity, and grain kinematics, against hand-computed values.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "io/list_files.hpp"
#include "contact/models.hpp"
#include "core/errors.hpp"
#include "lab/kinematics.hpp"
#include "lab/sphericity.hpp"

using namespace grainlab;
using namespace grainlab::contact;

namespace {

SphereContactModel linearModel() {
  SphereContactModel m;
  m.rolling = RollingLaw::Linear;
  return m;
}

// Drives one contact with B spinning relative to A about `axis` at `spin` for `steps` steps.
Vec3 driveMoment(const PairParams& p, const Vec3& axis, double spin, double overlap, int steps, double dt) {
  ContactHistory h;
  h.prevNormal = Vec3::UnitZ();
  h.touching = true;
  for (int i = 0; i < steps; ++i) {
    ContactKinematics k{Vec3::UnitZ(), h.prevNormal, overlap, Vec3::Zero(), spin * axis,
                        0.5 * spin * axis.dot(Vec3::UnitZ()), dt};
    applyLaw(p, k, h);
  }
  return h.moment;
}

}  // namespace

TEST(RollingLinear, BendingElasticThenPlateauNoTwisting) {
  const SphereContactModel m = linearModel();
  const double rA = 2e-3, rB = 3e-3, overlap = 1e-6, dt = 1e-6, spin = 2.0;
  const double muA = 0.3, muB = 0.1;
  const PairParams p = m.pairParams(rA, rB, muA, muB);
  const double kn = 2.0 * 30e9 * rA * rB / (rA + rB), ks = 0.3 * kn, rBar = rA * rB / (rA + rB);
  EXPECT_DOUBLE_EQ(p.kr, ks * rBar * rBar);
  const double limit = std::min(muA, muB) * kn * overlap * rBar;  // combine = min
  // Elastic: 10 steps of 2e-6 rad give kr * 2e-5 (below the limit).
  const Vec3 elastic = driveMoment(p, Vec3::UnitX(), spin, overlap, 10, dt);
  ASSERT_LT(p.kr * spin * dt * 10, limit);
  EXPECT_NEAR(elastic.x(), p.kr * spin * dt * 10, 1e-12 * limit);
  // Plateau at mu_r |Fn| R.
  const Vec3 plastic = driveMoment(p, Vec3::UnitX(), spin, overlap, 20000, dt);
  EXPECT_NEAR(plastic.norm(), limit, 1e-12 * limit);
  // Twisting (spin about the normal) meets no resistance in this model.
  EXPECT_EQ(driveMoment(p, Vec3::UnitZ(), spin, overlap, 100, dt).norm(), 0.0);
}

TEST(RollingLinear, CombineRules) {
  EXPECT_DOUBLE_EQ(combineRollingFriction(CombineRule::Min, 0.2, 0.6), 0.2);
  EXPECT_DOUBLE_EQ(combineRollingFriction(CombineRule::Mean, 0.2, 0.6), 0.4);
  EXPECT_DOUBLE_EQ(combineRollingFriction(CombineRule::Harmonic, 0.2, 0.6), 2 * 0.2 * 0.6 / 0.8);
  EXPECT_DOUBLE_EQ(combineRollingFriction(CombineRule::Harmonic, 0.0, 0.0), 0.0);
  SphereContactModel m = linearModel();
  m.combine = CombineRule::Mean;
  const double rBar = 1e-3 * 1e-3 / 2e-3;
  EXPECT_DOUBLE_EQ(m.pairParams(1e-3, 1e-3, 0.2, 0.6).momentLimitArm, 0.4 * rBar);
}

TEST(Sphericity, RollingFrictionFromSphericity) {
  EXPECT_DOUBLE_EQ(lab::rollingFrictionFromSphericity(0.8, 0.1963, -4.0), 0.1963 * std::pow(0.8, -4.0));
  // psi is capped at 1.
  EXPECT_DOUBLE_EQ(lab::rollingFrictionFromSphericity(1.2, 0.1963, -4.0), 0.1963);
}

TEST(Sphericity, SamplingReproducesHistogram) {
  lab::SphericityDistribution d;
  d.binLow = {0.6, 0.7, 0.8, 0.9};
  d.binHigh = {0.7, 0.8, 0.9, 1.0};
  d.frequency = {10, 30, 40, 20};
  lab::Rng rng(42);
  const std::size_t n = 20000;
  const std::vector<double> psi = lab::sampleSphericity(d, n, rng);
  std::vector<double> counts(4, 0.0);
  for (double v : psi) {
    ASSERT_GE(v, 0.6);
    ASSERT_LT(v, 1.0);
    counts[std::min(3, static_cast<int>((v - 0.6) / 0.1))] += 1.0;
  }
  // Pearson chi-square with 3 degrees of freedom: 11.34 is the 1 % critical value.
  double chi2 = 0.0;
  for (int b = 0; b < 4; ++b) {
    const double expected = n * d.frequency[b] / 100.0;
    chi2 += (counts[b] - expected) * (counts[b] - expected) / expected;
  }
  EXPECT_LT(chi2, 11.34);
  // Uniform within a bin: the mean of the top bin's draws is its centre.
  double sum = 0.0, m = 0.0;
  for (double v : psi)
    if (v >= 0.9) { sum += v; m += 1.0; }
  EXPECT_NEAR(sum / m, 0.95, 0.003);
}

TEST(Sphericity, SamplingFromAListDrawsItsValues) {
  lab::SphericityDistribution d;
  d.values = {0.7, 0.8, 0.9};
  lab::Rng rng(3);
  const std::vector<double> psi = lab::sampleSphericity(d, 30000, rng);
  std::vector<int> counts(3, 0);
  for (double v : psi) counts[static_cast<int>(std::lround((v - 0.7) / 0.1))]++;
  for (int c : counts) EXPECT_NEAR(c / 30000.0, 1.0 / 3.0, 0.01);
}

TEST(Sphericity, FileErrorsNameTheProblem) {
  const std::string path = ::testing::TempDir() + "/psi.csv";
  auto expectError = [&](const std::string& content, const std::string& fragment) {
    std::ofstream(path) << content;
    try {
      io::readSphericityFile(path, "contact.sphericity.file");
      ADD_FAILURE() << "no error for: " << content;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expectError("sphericity\n0.8\n-0.1\n", "must be > 0");
  expectError("bin_low,bin_high,frequency\n0.6,0.7,-3\n", "must be >= 0");
  expectError("sphericity\n", "no data rows");
  expectError("diameter\n0.8\n", "header");
  expectError("bin_low,bin_high,frequency\n0.7,0.6,3\n", "bin_low < bin_high");
}

// A rigid rotation of the whole sample: every grain's rotation is the imposed one, and no grain
// shows local strain or belongs to a band.
TEST(Kinematics, PrescribedRigidRotation) {
  Simulation sim;
  Particles& p = sim.particles;
  lab::Rng rng(5);
  for (int i = 0; i < 300; ++i)
    p.addSphere(Vec3(rng.uniform(0, 0.05), rng.uniform(0, 0.05), rng.uniform(0, 0.05)), 2e-3, 2600.0);
  lab::GrainRecords records;
  records.reset(sim);
  const Eigen::AngleAxisd rotation(degToRad(17.0), Vec3(1.0, 2.0, 0.5).normalized());
  const Vec3 centre(0.025, 0.025, 0.025);
  for (std::size_t i = 0; i < p.size(); ++i) {
    p.position[i] = centre + rotation * (p.position[i] - centre);
    p.orientation[i] = Quat(rotation) * p.orientation[i];
  }
  const lab::GrainKinematics k = lab::grainKinematics(sim, records, Mat3::Zero(), 0.012);
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(k.rotationDeg[i], 17.0, 1e-9);
    EXPECT_LT(k.localShearStrain[i], 1e-12);
    EXPECT_EQ(k.inBand[i], 0.0);
  }
  EXPECT_NEAR(k.rotationMeanDeg, 17.0, 1e-9);
  // No homogeneous strain, no band criterion: the band's values are not measured (NaN), not 0.
  EXPECT_TRUE(std::isnan(k.bandFraction));
  EXPECT_TRUE(std::isnan(k.rotationBandMeanDeg));
  EXPECT_TRUE(std::isnan(k.rotationOutsideMeanDeg));
}

// A band of simple shear through the middle of a block: the sheared layer is detected as the band.
TEST(Kinematics, ShearBandIsDetected) {
  Simulation sim;
  Particles& p = sim.particles;
  for (int x = 0; x < 12; ++x)
    for (int y = 0; y < 12; ++y)
      for (int z = 0; z < 12; ++z) p.addSphere(Vec3(x, y, z) * 4e-3, 2e-3, 2600.0);
  lab::GrainRecords records;
  records.reset(sim);
  // Displacement along x that grows with z only inside 20 mm < z < 28 mm (a shear of 0.2 there).
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double z = records.referencePosition[i].z();
    p.position[i].x() += 0.2 * std::clamp(z - 0.020, 0.0, 0.008);
  }
  // The box's average shear: 0.2 * 8 mm over 44 mm, as a pure-shear-equivalent diagonal strain.
  Mat3 box = Mat3::Zero();
  box(0, 2) = box(2, 0) = 0.5 * 0.2 * 8.0 / 44.0;
  const lab::GrainKinematics k = lab::grainKinematics(sim, records, box, 4.5e-3);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double z = records.referencePosition[i].z();
    if (z > 0.0205 && z < 0.0275) EXPECT_EQ(k.inBand[i], 1.0) << "z = " << z;
    if (z < 0.015 || z > 0.033) EXPECT_EQ(k.inBand[i], 0.0) << "z = " << z;
  }
  // The threshold is the band factor: the layer shears ~44/8 = 5.5 times more than the box on
  // average, so a factor of 20 finds no band and a lower factor finds at least the same grains.
  EXPECT_GT(k.bandFraction, 0.0);
  const lab::GrainKinematics strict = lab::grainKinematics(sim, records, box, 4.5e-3, 20.0);
  EXPECT_EQ(strict.bandFraction, 0.0);
  EXPECT_TRUE(std::isnan(strict.rotationBandMeanDeg));  // a mean over no grain
  EXPECT_FALSE(std::isnan(strict.rotationOutsideMeanDeg));
  const lab::GrainKinematics loose = lab::grainKinematics(sim, records, box, 4.5e-3, 1.2);
  EXPECT_GE(loose.bandFraction, k.bandFraction);

  // The spread of the rotations: the band's grains turned by 10 and 20 deg alternately (a fraction q
  // by 20: mean 10 + 10 q, standard deviation 10 sqrt(q (1 - q))), the others not at all (0, 0).
  std::size_t inBand = 0, by20 = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (k.inBand[i] < 0.5) continue;
    const double deg = inBand++ % 2 ? 20.0 : 10.0;
    by20 += deg == 20.0;
    p.orientation[i] = Quat(Eigen::AngleAxisd(degToRad(deg), Vec3::UnitY())) * p.orientation[i];
  }
  const lab::GrainKinematics turned = lab::grainKinematics(sim, records, box, 4.5e-3);
  const double q = static_cast<double>(by20) / static_cast<double>(inBand);
  EXPECT_NEAR(turned.rotationBandMeanDeg, 10.0 + 10.0 * q, 1e-9);
  EXPECT_NEAR(turned.rotationBandStdDeg, 10.0 * std::sqrt(q * (1.0 - q)), 1e-9);
  EXPECT_NEAR(turned.rotationOutsideMeanDeg, 0.0, 1e-9);
  EXPECT_NEAR(turned.rotationOutsideStdDeg, 0.0, 1e-9);
  EXPECT_TRUE(std::isnan(strict.rotationBandStdDeg));  // below two grains
}

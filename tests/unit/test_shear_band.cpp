// The shear band's plane and thickness (lab/shear_band.hpp) on synthetic strain fields whose band
// is known: a slab of given inclination and width, a Gaussian profile (full width at half height
// 2 sqrt(2 ln 2) sigma), and fields with no band (homogeneous, scattered, everywhere).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lab/shear_band.hpp"

using namespace grainlab;

namespace {

constexpr double kD = 1e-3;  // lattice spacing = d50 [m]

struct Field {
  std::vector<Vec3> position;
  std::vector<double> strain, inBand;
};

// A 24 x 24 x 48 lattice; eq = background + f(s), s the distance to the plane through the sample's
// centre with the given normal; in the band where eq >= 2 x 0.03 (the band criterion, factor 2).
template <class Profile>
Field lattice(const Vec3& normal, Profile f) {
  Field out;
  const Vec3 centre(11.5 * kD, 11.5 * kD, 23.5 * kD);
  // Grains off the lattice sites by up to 0.3 d50, as in a packing (a lattice's rows would favour
  // its own directions).
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  for (int x = 0; x < 24; ++x)
    for (int y = 0; y < 24; ++y)
      for (int z = 0; z < 48; ++z) {
        const Vec3 p = (Vec3(x, y, z) + Vec3(jitter(rng), jitter(rng), jitter(rng))) * kD;
        const double eq = 0.01 + f(normal.dot(p - centre));
        out.position.push_back(p);
        out.strain.push_back(eq);
        out.inBand.push_back(eq >= 0.06 ? 1.0 : 0.0);
      }
  return out;
}

Vec3 inclined(double deg) {
  const double a = deg * M_PI / 180.0;
  return Vec3(std::sin(a), 0.0, std::cos(a));
}

lab::ShearBandSettings settings() {
  lab::ShearBandSettings s;
  s.binWidth = kD;
  return s;
}

std::optional<lab::ShearBand> find(const Field& f) {
  return lab::findShearBand(f.position, f.strain, f.inBand, {}, settings());
}

}  // namespace

// A slab 8 d50 thick inclined at 60 deg to the horizontal: its angle, its normal and its width.
TEST(ShearBand, InclinedSlabIsFoundWithItsAngleAndThickness) {
  const Vec3 n = inclined(60.0);
  const auto band = find(lattice(n, [](double s) { return std::abs(s) < 4.0 * kD ? 0.2 : 0.0; }));
  ASSERT_TRUE(band);
  EXPECT_NEAR(band->inclinationDeg, 60.0, 0.5);
  EXPECT_GT(band->normal.dot(n), 0.999);
  EXPECT_NEAR(band->thickness / kD, 8.0, 0.6);
  EXPECT_NEAR(band->backgroundStrain, 0.01, 1e-12);
  EXPECT_NEAR(band->peakStrain, 0.21, 1e-9);
  EXPECT_LT(band->flatness, 0.25);
}

// A Gaussian profile of sigma = 3 d50: full width at half height 2 sqrt(2 ln 2) sigma = 7.06 d50.
TEST(ShearBand, GaussianProfileGivesItsFullWidthAtHalfHeight) {
  const double sigma = 3.0 * kD;
  const auto band = find(lattice(inclined(35.0), [&](double s) { return 0.2 * std::exp(-s * s / (2 * sigma * sigma)); }));
  ASSERT_TRUE(band);
  EXPECT_NEAR(band->inclinationDeg, 35.0, 0.5);
  EXPECT_NEAR(band->thickness / sigma, 2.0 * std::sqrt(2.0 * std::log(2.0)), 0.1);
}

// Horizontal and vertical bands: 0 and 90 deg (the angle is the plane's, not its normal's).
TEST(ShearBand, HorizontalAndVerticalBands) {
  auto slab = [](double s) { return std::abs(s) < 3.0 * kD ? 0.2 : 0.0; };
  const auto flat = find(lattice(Vec3::UnitZ(), slab));
  ASSERT_TRUE(flat);
  EXPECT_NEAR(flat->inclinationDeg, 0.0, 0.1);
  const auto upright = find(lattice(Vec3::UnitX(), slab));
  ASSERT_TRUE(upright);
  EXPECT_NEAR(upright->inclinationDeg, 90.0, 0.1);
  EXPECT_NEAR(upright->thickness / kD, 6.0, 0.6);
}

// No localisation, no band: a homogeneous field with noise (nothing flagged), grains flagged at
// random through the sample (not a slab), and most of the sample flagged (no contrast).
TEST(ShearBand, NoBandWithoutLocalisation) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Field f = lattice(Vec3::UnitZ(), [](double) { return 0.02; });
  for (double& e : f.strain) e *= 0.9 + 0.2 * u(rng);
  EXPECT_FALSE(find(f));

  Field scattered = f;
  for (std::size_t i = 0; i < scattered.strain.size(); ++i)
    if (u(rng) < 0.2) {
      scattered.strain[i] = 0.2;
      scattered.inBand[i] = 1.0;
    }
  EXPECT_FALSE(find(scattered));

  const Field everywhere = lattice(Vec3::UnitZ(), [](double s) { return std::abs(s) < 20.0 * kD ? 0.2 : 0.0; });
  EXPECT_FALSE(find(everywhere));
}

// Only load-bearing grains count: a band made only of rattlers is no band.
TEST(ShearBand, RattlersAreLeftOut) {
  const Field f = lattice(inclined(60.0), [](double s) { return std::abs(s) < 4.0 * kD ? 0.2 : 0.0; });
  std::vector<char> active(f.position.size());
  for (std::size_t i = 0; i < active.size(); ++i) active[i] = f.inBand[i] < 0.5;
  EXPECT_FALSE(lab::findShearBand(f.position, f.strain, f.inBand, active, settings()));
  EXPECT_TRUE(lab::findShearBand(f.position, f.strain, f.inBand, std::vector<char>(active.size(), 1), settings()));
}

// Void ratios inside and outside the band against a simple cubic packing, e = 6/pi - 1 = 0.9099
// for touching spheres; with the spheres inside an inclined slab shrunk to 0.4 of the spacing,
// e inside = 1/(4/3 pi 0.4^3) - 1 = 2.730 and outside still 0.9099.
TEST(ShearBand, VoidRatiosInsideAndOutsideTheBand) {
  lab::ShearBand band;
  band.normal = inclined(60.0);
  band.centre = Vec3(12.0, 12.0, 24.0) * kD;
  band.thickness = 8.0 * kD;
  std::vector<Vec3> position, axes, small;
  for (int x = 0; x < 24; ++x)
    for (int y = 0; y < 24; ++y)
      for (int z = 0; z < 48; ++z) {
        const Vec3 p = Vec3(x + 0.5, y + 0.5, z + 0.5) * kD;
        position.push_back(p);
        axes.push_back(Vec3::Constant(0.5 * kD));
        const bool in = std::abs(band.normal.dot(p - band.centre)) <= 0.5 * band.thickness;
        small.push_back(Vec3::Constant((in ? 0.4 : 0.5) * kD));
      }
  const Vec3 lo = Vec3::Zero(), hi = Vec3(24, 24, 48) * kD;
  const double sc = 6.0 / M_PI - 1.0;
  const auto uniform = lab::bandVoidRatios(band, position, axes, lo, hi);
  ASSERT_TRUE(uniform);
  EXPECT_NEAR(uniform->inside, sc, 0.02);
  EXPECT_NEAR(uniform->outside, sc, 0.01);
  const auto loose = lab::bandVoidRatios(band, position, small, lo, hi);
  ASSERT_TRUE(loose);
  EXPECT_NEAR(loose->inside, 1.0 / (4.0 / 3.0 * M_PI * 0.064) - 1.0, 0.12);
  EXPECT_NEAR(loose->outside, sc, 0.03);
  // A membrane sample: only the points the predicate keeps are the sample. The lattice's cylinder
  // of radius 10 d about the box's axis (its grains only) in a box twice as wide: the same void
  // ratios as the lattice, where counting the empty box around it would make them far looser.
  std::vector<Vec3> inCylinder, cylinderAxes;
  const Vec3 axis(12.0 * kD, 12.0 * kD, 0.0);
  auto within = [&](const Vec3& x) { return std::hypot(x.x() - axis.x(), x.y() - axis.y()) <= 10.0 * kD; };
  for (std::size_t i = 0; i < position.size(); ++i)
    if (within(position[i])) inCylinder.push_back(position[i]), cylinderAxes.push_back(axes[i]);
  const Vec3 wideLo = Vec3(-12, -12, 0) * kD, wideHi = Vec3(36, 36, 48) * kD;
  const auto cylinder = lab::bandVoidRatios(band, inCylinder, cylinderAxes, wideLo, wideHi, within);
  ASSERT_TRUE(cylinder);
  EXPECT_NEAR(cylinder->inside, sc, 0.05);
  EXPECT_NEAR(cylinder->outside, sc, 0.05);
  const auto box = lab::bandVoidRatios(band, inCylinder, cylinderAxes, wideLo, wideHi);
  ASSERT_TRUE(box);
  EXPECT_GT(box->outside, 3.0 * sc);
}

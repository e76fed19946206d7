// The layered sample of sample.method = "under-compaction" (docs/laboratory.md 1.8), by hand:
//   solidVolumeBetween: a sphere wholly between the planes counts 4/3 pi r^3, a plane through its
//   centre halves it, a cap of height h counts pi h^2 (3r - h)/3 (h = r/2: 5/24 pi r^3), and the
//   slices of a stack add up to the whole solid volume;
//   appendSlab: the new grains follow the old ones (ids and order), lie above zBottom inside the
//   footprint, overlap nothing, and fill a slab of the requested void ratio.
#include <gtest/gtest.h>

#include <cmath>

#include "lab/placement.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

namespace {

constexpr double kLayerR = 1e-3, kLayerRho = 2600.0;

Particles oneSphereAt(double z) {
  Particles p;
  p.addSphere(Vec3(0.0, 0.0, z), kLayerR, kLayerRho);
  return p;
}

double sphereVolume(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

}  // namespace

TEST(Layers, SolidVolumeBetweenPlanesByHand) {
  const Particles p = oneSphereAt(0.0);
  EXPECT_NEAR(lab::solidVolumeBetween(p, -2 * kLayerR, 2 * kLayerR) / sphereVolume(kLayerR), 1.0, 1e-12);
  EXPECT_NEAR(lab::solidVolumeBetween(p, 0.0, 5 * kLayerR) / sphereVolume(kLayerR), 0.5, 1e-12);
  EXPECT_NEAR(lab::solidVolumeBetween(p, -5 * kLayerR, 0.0) / sphereVolume(kLayerR), 0.5, 1e-12);
  // A cap of height r/2 at the top: 5/24 pi r^3.
  EXPECT_NEAR(lab::solidVolumeBetween(p, 0.5 * kLayerR, 3 * kLayerR) / (5.0 / 24.0 * kPi * kLayerR * kLayerR * kLayerR), 1.0, 1e-12);
  EXPECT_EQ(lab::solidVolumeBetween(p, 2 * kLayerR, 3 * kLayerR), 0.0);
}

TEST(Layers, SlicesOfAStackAddUpToItsSolidVolume) {
  Particles p;
  double total = 0.0;
  for (int k = 0; k < 7; ++k) {
    const double r = kLayerR * (0.6 + 0.1 * k);
    p.addSphere(Vec3(0.1 * k * kLayerR, 0.0, 1.7 * kLayerR * k), r, kLayerRho);
    total += sphereVolume(r);
  }
  double sum = 0.0;
  for (int s = 0; s < 13; ++s) sum += lab::solidVolumeBetween(p, -kLayerR + s * kLayerR, s * kLayerR);
  EXPECT_NEAR(sum / total, 1.0, 1e-12);
}

TEST(Layers, AppendSlabPlacesAboveTheBedWithoutOverlaps) {
  Simulation sim = scenes::emptyScene(0.05);
  lab::Rng rng(11);
  const double width = 0.005, voidRatio = 2.0;  // both slabs above the 2 d minimum height
  std::vector<double> first(40, 1.2e-3), second(80, 1.0e-3);
  const double h1 = lab::appendSlab(first, kLayerRho, voidRatio, width, 0.0, rng, sim);
  ASSERT_EQ(sim.particles.size(), 40u);
  double top = 0.0;
  for (std::size_t i = 0; i < sim.particles.size(); ++i)
    top = std::max(top, sim.particles.position[i].z() + sim.particles.radius[i]);
  EXPECT_LE(top, h1 + 1e-12);
  const double h2 = lab::appendSlab(second, kLayerRho, voidRatio, width, top, rng, sim);
  const Particles& P = sim.particles;
  ASSERT_EQ(P.size(), 120u);
  double solid = 0.0;
  for (std::size_t i = 40; i < P.size(); ++i) {
    EXPECT_EQ(P.radius[i], 0.5e-3) << "the second slab's grains follow the first's";
    EXPECT_GE(P.position[i].z() - P.radius[i], top - 1e-12);
    EXPECT_LE(P.position[i].z() + P.radius[i], top + h2 + 1e-12);
    for (int a = 0; a < 2; ++a) {
      EXPECT_GE(P.position[i][a] - P.radius[i], -1e-12);
      EXPECT_LE(P.position[i][a] + P.radius[i], width + 1e-12);
    }
    solid += sphereVolume(P.radius[i]);
  }
  for (std::size_t i = 0; i < 40; ++i) EXPECT_EQ(P.radius[i], 0.6e-3) << "the first slab is left as it was";
  for (std::size_t i = 0; i < P.size(); ++i)
    for (std::size_t j = i + 1; j < P.size(); ++j)
      EXPECT_GE((P.position[i] - P.position[j]).norm(), P.radius[i] + P.radius[j] - 1e-12) << i << " " << j;
  // The slab holds the requested void ratio, or a looser one where it had to grow in 5 % steps (in a
  // footprint 5 d wide the walls keep the centres from a fifth of it).
  EXPECT_GE(width * width * h2 / solid - 1.0, voidRatio - 1e-9);
  EXPECT_LE(width * width * h2 / solid - 1.0, (1.0 + voidRatio) * 1.5 - 1.0);
}

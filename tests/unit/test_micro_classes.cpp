// Orientation classes: the partition covers the sphere once, every class area equals an
// independent closed form (Girard's theorem on the patch's great-circle corners), and the
// quadrature moments are those of the sphere.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lab/orientation_classes.hpp"

using namespace grainlab;
using grainlab::lab::OrientationClasses;

namespace {

// Area of a spherical polygon bounded by great circles: sum of interior angles − (n − 2)π.
double girardArea(const std::array<Vec3, 4>& c) {
  double angles = 0.0;
  for (int v = 0; v < 4; ++v) {
    const Vec3& p = c[v];
    const Vec3& prev = c[(v + 3) % 4];
    const Vec3& next = c[(v + 1) % 4];
    // Tangents at p of the great circles towards prev and next.
    const Vec3 t1 = (prev - prev.dot(p) * p).normalized();
    const Vec3 t2 = (next - next.dot(p) * p).normalized();
    angles += std::acos(std::clamp(t1.dot(t2), -1.0, 1.0));
  }
  return angles - 2.0 * kPi;
}

Vec3 randomDirection(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

}  // namespace

TEST(OrientationClasses, CountIs24TimesNSquared) {
  for (int n : {1, 2, 4, 6}) EXPECT_EQ(OrientationClasses(n).size(), static_cast<std::size_t>(24 * n * n));
  EXPECT_THROW(OrientationClasses(0), std::invalid_argument);
}

TEST(OrientationClasses, AreasSumTo4PiAndMatchGirard) {
  for (int n : {1, 2, 4, 5}) {
    const OrientationClasses oc(n);
    double total = 0.0, smallest = 1e9, largest = 0.0;
    for (std::size_t k = 0; k < oc.size(); ++k) {
      total += oc.area(k);
      smallest = std::min(smallest, oc.area(k));
      largest = std::max(largest, oc.area(k));
      EXPECT_NEAR(oc.area(k), girardArea(oc.corners(k)), 1e-12 * oc.area(k) + 1e-14) << "class " << k;
      // The quadrature of the patch (trace of its second moment) agrees with the closed form.
      EXPECT_NEAR(oc.secondMoment(k).trace(), oc.area(k), 1e-13) << "class " << k;
    }
    EXPECT_NEAR(total, 4.0 * kPi, 1e-12);
    // Near-uniform: the equiangular cube-sphere's patches differ by at most √2 (edge vs centre).
    EXPECT_LT(largest / smallest, 1.45);
  }
}

TEST(OrientationClasses, N4AreasOfFirstPatchesByHand) {
  // Face +z, cells of 22.5°: the corner patch [−45°, −22.5°]² and the central patch [0, 22.5°]².
  const double t1 = std::tan(kPi / 8), t2 = 1.0;
  const double F11 = std::atan(t2 * t2 / std::sqrt(1 + 2 * t2 * t2));
  const double F12 = std::atan(t1 * t2 / std::sqrt(1 + t1 * t1 + t2 * t2));
  const double F22 = std::atan(t1 * t1 / std::sqrt(1 + 2 * t1 * t1));
  const double corner = F11 - 2 * F12 + F22;  // [t1, 1]² by symmetry
  const double centre = F22;                  // [0, t1]²
  EXPECT_NEAR(OrientationClasses::gnomonicRectangleArea(t1, 1, t1, 1), corner, 1e-15);
  EXPECT_NEAR(OrientationClasses::gnomonicRectangleArea(0, t1, 0, t1), centre, 1e-15);
  // The face is one sixth of the sphere.
  EXPECT_NEAR(OrientationClasses::gnomonicRectangleArea(-1, 1, -1, 1), 4 * kPi / 6, 1e-15);
}

TEST(OrientationClasses, MomentsSumToThoseOfTheSphere) {
  const OrientationClasses oc(4);
  Vec3 m1 = Vec3::Zero();
  Mat3 m2 = Mat3::Zero();
  lab::Tensor4 m4{};
  for (std::size_t k = 0; k < oc.size(); ++k) {
    m1 += oc.firstMoment(k);
    m2 += oc.secondMoment(k);
    for (std::size_t c = 0; c < 81; ++c) m4[c] += oc.fourthMoment(k)[c];
  }
  EXPECT_LT(m1.norm(), 1e-13);
  EXPECT_LT((m2 - 4 * kPi / 3 * Mat3::Identity()).norm(), 1e-13);
  auto d = [](int i, int j) { return i == j ? 1.0 : 0.0; };
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l)
          EXPECT_NEAR(m4[((i * 3 + j) * 3 + k) * 3 + l],
                      4 * kPi / 15 * (d(i, j) * d(k, l) + d(i, k) * d(j, l) + d(i, l) * d(j, k)), 1e-13);
}

TEST(OrientationClasses, EveryDirectionLiesInsideItsPatch) {
  const OrientationClasses oc(4);
  std::mt19937_64 rng(12);
  for (int trial = 0; trial < 20000; ++trial) {
    const Vec3 n = randomDirection(rng);
    const std::size_t k = oc.classOf(n);
    const auto c = oc.corners(k);
    for (int e = 0; e < 4; ++e) {
      // Counter-clockwise corners: inside means left of every edge's great circle.
      const Vec3 edgeNormal = c[e].cross(c[(e + 1) % 4]);
      EXPECT_GE(edgeNormal.dot(n), -1e-12) << "direction " << n.transpose() << " class " << k;
    }
  }
  for (std::size_t k = 0; k < oc.size(); ++k) EXPECT_EQ(oc.classOf(oc.centre(k)), k);
}

TEST(OrientationClasses, CentrallySymmetric) {
  const OrientationClasses oc(3);
  for (std::size_t k = 0; k < oc.size(); ++k) {
    const std::size_t m = oc.classOf(-oc.centre(k));
    EXPECT_NEAR(oc.area(m), oc.area(k), 1e-15);
    EXPECT_LT((oc.centre(m) + oc.centre(k)).norm(), 1e-14);
  }
  // Also for directions on patch boundaries, edges and corners of the cube (lattice normals).
  std::vector<Vec3> special;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x || y || z) special.emplace_back(x, y, z);
  for (const Vec3& n : special) {
    const std::size_t k = oc.classOf(n), m = oc.classOf(-n);
    EXPECT_NE(k, m);
    EXPECT_LT((oc.centre(m) + oc.centre(k)).norm(), 1e-14) << n.transpose();
  }
}

TEST(OrientationClasses, UniformDirectionsFillClassesInProportionToArea) {
  // Chi-square of 200 000 uniform directions over the 96 classes of N = 2: 95 degrees of freedom,
  // mean 95, standard deviation 13.8; a mapping that ignored the area law fails by thousands.
  const OrientationClasses oc(2);
  std::mt19937_64 rng(3);
  std::vector<double> hits(oc.size(), 0.0);
  const int draws = 200000;
  for (int t = 0; t < draws; ++t) hits[oc.classOf(randomDirection(rng))] += 1.0;
  double chi2 = 0.0;
  for (std::size_t k = 0; k < oc.size(); ++k) {
    const double expected = draws * oc.area(k) / (4 * kPi);
    chi2 += (hits[k] - expected) * (hits[k] - expected) / expected;
  }
  EXPECT_LT(chi2, 95 + 4 * 13.8);
}

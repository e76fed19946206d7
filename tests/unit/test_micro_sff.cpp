// Stress–force–fabric relation: the library integrates the product of the truncated densities
// exactly (monomial moments); here the same integral is done by numerical quadrature on the
// sphere, and the sphere's second-order closed form is derived by hand.
#include <gtest/gtest.h>

#include <boost/math/quadrature/gauss.hpp>

#include <algorithm>
#include <random>

#include "lab/micromechanics.hpp"

using namespace grainlab;
using namespace grainlab::lab;

namespace {

Mat3 randomDeviator(std::mt19937_64& rng, double size) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat3 a;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) a(i, j) = a(j, i) = u(rng);
  a -= a.trace() / 3.0 * Mat3::Identity();
  return size * a / std::sqrt(1.5 * (a.array() * a.array()).sum());
}

Tensor4 randomDeviator4(std::mt19937_64& rng, double size) {
  // Symmetrise random values, then remove the traces.
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Tensor4 raw{}, sym{};
  for (double& v : raw) v = u(rng);
  int perm[24][4];
  int p[4] = {0, 1, 2, 3}, m = 0;
  std::sort(p, p + 4);
  do {
    std::copy(p, p + 4, perm[m++]);
  } while (std::next_permutation(p, p + 4));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) {
          const int idx[4] = {i, j, k, l};
          double s = 0.0;
          for (auto& q : perm) s += raw[((idx[q[0]] * 3 + idx[q[1]]) * 3 + idx[q[2]]) * 3 + idx[q[3]]];
          sym[((i * 3 + j) * 3 + k) * 3 + l] = s / 24.0;
        }
  Tensor4 d = deviator4(sym);
  const double scale = size / norm4(d);
  for (double& v : d) v *= scale;
  return d;
}

// (1/4π)∫ g(n) dΩ by 24-point Gauss–Legendre in cos θ and 48 equal steps in φ: exact for
// polynomials of degree < 48 in n, far above the degree 14 of the richest integrand here.
template <class F>
Mat3 sphereMean(F&& integrand) {
  using Rule = boost::math::quadrature::gauss<double, 24>;
  const auto& x = Rule::abscissa();
  const auto& w = Rule::weights();
  const int nphi = 48;
  Mat3 s = Mat3::Zero();
  for (std::size_t a = 0; a < x.size(); ++a)
    for (double sign : {-1.0, 1.0}) {
      const double z = sign * x[a];
      const double r = std::sqrt(1.0 - z * z);
      for (int k = 0; k < nphi; ++k) {
        const double phi = 2.0 * kPi * k / nphi;
        s += w[a] * (2.0 * kPi / nphi) * integrand(Vec3(r * std::cos(phi), r * std::sin(phi), z));
      }
    }
  return s / (4.0 * kPi);
}

// m_v f0 l0 ∫ E F̂ ⊗ L̂ dΩ evaluated pointwise from the definitions (docs/physics.md §11, [O] ch. 6).
Mat3 quadratureStress(const SffTerms& t) {
  return t.mv * t.f0 * t.l0 * sphereMean([&](const Vec3& n) -> Mat3 {
           double e = 1.0 + n.dot(t.ar * n);
           double fn = 1.0 + n.dot(t.an * n);
           if (t.ar4) e += contract4(*t.ar4, n);
           if (t.an4) fn += contract4(*t.an4, n);
           const Vec3 f = fn * n + t.at * n - n.dot(t.at * n) * n;
           const Vec3 l = (1.0 + n.dot(t.av * n)) * n + t.atau * n - n.dot(t.atau * n) * n;
           return e * f * l.transpose();
         });
}

}  // namespace

TEST(StressForceFabric, FullRelationEqualsQuadratureOfTheStressIntegral) {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    SffTerms t;
    t.mv = 1e6;
    t.f0 = 3.0;
    t.l0 = 2e-3;
    t.ar = randomDeviator(rng, 0.4);
    t.an = randomDeviator(rng, 0.5);
    t.at = randomDeviator(rng, 0.2);
    if (trial % 2) {  // non-spherical: branch terms
      t.av = randomDeviator(rng, 0.1);
      t.atau = randomDeviator(rng, 0.05);
    }
    if (trial % 4 >= 2) {
      t.ar4 = randomDeviator4(rng, 0.3);
      t.an4 = randomDeviator4(rng, 0.3);
    }
    const Mat3 exact = sffStress(t);
    const Mat3 quad = quadratureStress(t);
    EXPECT_LT((exact - quad).norm(), 1e-12 * quad.norm()) << "trial " << trial << "\n" << exact << "\n" << quad;
  }
}

TEST(StressForceFabric, SpheresSecondOrderClosedForm) {
  // Derived by hand with <n_i n_j> = δ/3, <n_i n_j n_k n_l> = (δδ + δδ + δδ)/15 and the sixth
  // moment (15 pairings)/105, for traceless symmetric a^r, a^n, a^t:
  //   σ/(m_v f0 l0) = δ/3 + 2/15 (a^r + a^n) + 1/5 a^t
  //                 + 2/105 δ (a^r:a^n) + 4/105 (a^r a^n + a^n a^r)
  //                 + 2/15 a^t a^r − 2/105 δ (a^r:a^t) − 4/105 (a^r a^t + a^t a^r).
  std::mt19937_64 rng(9);
  for (int trial = 0; trial < 10; ++trial) {
    SffTerms t;
    t.mv = 2.0;
    t.f0 = 5.0;
    t.l0 = 0.5;
    t.ar = randomDeviator(rng, 0.6);
    t.an = randomDeviator(rng, 0.7);
    t.at = randomDeviator(rng, 0.3);
    const Mat3 I = Mat3::Identity();
    auto dd = [](const Mat3& a, const Mat3& b) { return (a.array() * b.array()).sum(); };
    const Mat3& r = t.ar;
    const Mat3& n = t.an;
    const Mat3& s = t.at;
    const Mat3 hand = I / 3 + 2.0 / 15 * (r + n) + s / 5 + 2.0 / 105 * dd(r, n) * I + 4.0 / 105 * (r * n + n * r) +
                      2.0 / 15 * s * r - 2.0 / 105 * dd(r, s) * I - 4.0 / 105 * (r * s + s * r);
    const Mat3 lib = sffStress(t) / (t.mv * t.f0 * t.l0);
    EXPECT_LT((lib - hand).norm(), 1e-14);
    // First order: drop the products.
    const Mat3 linear = sffStressLinear(t) / (t.mv * t.f0 * t.l0);
    EXPECT_LT((linear - (I / 3 + 2.0 / 15 * (r + n) + s / 5)).norm(), 1e-15);
  }
}

TEST(StressForceFabric, AxisymmetricFirstOrderGivesTwoFifthsRule) {
  // a = diag(−a/3, −a/3, 2a/3) has a_zz − a_xx = a = √(3/2 a:a): q/p = 2/5 (a_r + a_n + 3/2 a_t).
  auto axi = [](double a) { return Mat3(Vec3(-a / 3, -a / 3, 2 * a / 3).asDiagonal()); };
  SffTerms t;
  t.mv = t.f0 = t.l0 = 1.0;
  t.ar = axi(0.3);
  t.an = axi(0.5);
  t.at = axi(0.1);
  EXPECT_NEAR(*qOverP(sffStressLinear(t), 2), 0.4 * (0.3 + 0.5 + 1.5 * 0.1), 1e-15);
  EXPECT_NEAR(anisotropyOf(t.ar, axi(1.0)).magnitude, 0.3, 1e-15);
  EXPECT_NEAR(anisotropyOf(t.ar, axi(-1.0)).magnitude, -0.3, 1e-15);  // opposed to the stress
}

TEST(StressForceFabric, FourthOrderDeviatorIsTracelessAndProjectsWithKanataniFactor) {
  // For harmonic A, (1/4π)∫ (A::nnnn) dev4(nnnn) dΩ = 8/315 A: the factor 315/8 of a^(4).
  std::mt19937_64 rng(2);
  const Tensor4 A = randomDeviator4(rng, 1.0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double trace = 0.0;
      for (int k = 0; k < 3; ++k) trace += A[((i * 3 + j) * 3 + k) * 3 + k];
      EXPECT_NEAR(trace, 0.0, 1e-15);
    }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) {
        const Mat3 proj = sphereMean([&](const Vec3& n) -> Mat3 {
          Tensor4 nnnn{};
          for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
              for (int c = 0; c < 3; ++c)
                for (int d = 0; d < 3; ++d) nnnn[((a * 3 + b) * 3 + c) * 3 + d] = n[a] * n[b] * n[c] * n[d];
          const Tensor4 dev = deviator4(nnnn);
          Mat3 out;
          for (int l = 0; l < 3; ++l) out.row(l).setConstant(contract4(A, n) * dev[((i * 3 + j) * 3 + k) * 3 + l]);
          return out;
        });
        for (int l = 0; l < 3; ++l) EXPECT_NEAR(proj(l, 0), 8.0 / 315.0 * A[((i * 3 + j) * 3 + k) * 3 + l], 1e-15);
      }
}

#include "lab/orientation_classes.hpp"

#include <boost/math/quadrature/gauss.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace grainlab::lab {

namespace {

constexpr double kQuarterPi = kPi / 4.0;

// The 8 Gauss–Legendre nodes and weights on [−1, 1] (Boost stores the non-negative half).
struct GaussRule {
  std::array<double, 8> x{}, w{};
  GaussRule() {
    using Rule = boost::math::quadrature::gauss<double, 8>;
    const auto& a = Rule::abscissa();
    const auto& wt = Rule::weights();
    for (std::size_t m = 0; m < 4; ++m) {
      x[m] = -a[m];
      w[m] = wt[m];
      x[4 + m] = a[m];
      w[4 + m] = wt[m];
    }
  }
};

}  // namespace

OrientationClasses::OrientationClasses(int divisions) : divisions_(divisions) {
  if (divisions < 1 || divisions > 64)
    throw std::invalid_argument("orientation classes: divisions must be between 1 and 64");
  const int cells = 2 * divisions;  // angle cells per face coordinate
  const double h = (kPi / 2.0) / cells;
  const std::size_t n = static_cast<std::size_t>(6 * cells * cells);
  area_.resize(n);
  centre_.resize(n);
  first_.resize(n);
  second_.resize(n);
  third_.resize(n);
  fourth_.resize(n);
  static const GaussRule rule;
  for (std::size_t k = 0; k < n; ++k) {
    const Patch p = patch(k);
    const double a1 = -kQuarterPi + p.i * h, a2 = a1 + h;
    const double b1 = -kQuarterPi + p.j * h, b2 = b1 + h;
    area_[k] = gnomonicRectangleArea(std::tan(a1), std::tan(a2), std::tan(b1), std::tan(b2));
    centre_[k] = direction(p.face, a1 + h / 2, b1 + h / 2);
    Vec3 m1 = Vec3::Zero();
    Mat3 m2 = Mat3::Zero();
    Tensor3 m3{};
    Tensor4 m4{};
    for (int qa = 0; qa < 8; ++qa)
      for (int qb = 0; qb < 8; ++qb) {
        const double alpha = a1 + 0.5 * h * (1.0 + rule.x[qa]);
        const double beta = b1 + 0.5 * h * (1.0 + rule.x[qb]);
        const double ta = std::tan(alpha), tb = std::tan(beta);
        // dΩ = sec²α sec²β / (1 + tan²α + tan²β)^(3/2) dα dβ on the equiangular face.
        const double jac = (1.0 + ta * ta) * (1.0 + tb * tb) / std::pow(1.0 + ta * ta + tb * tb, 1.5);
        const double w = rule.w[qa] * rule.w[qb] * 0.25 * h * h * jac;
        const Vec3 d = direction(p.face, alpha, beta);
        m1 += w * d;
        m2 += w * d * d.transpose();
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            for (int l = 0; l < 3; ++l) {
              m3[(i * 3 + j) * 3 + l] += w * d[i] * d[j] * d[l];
              for (int m = 0; m < 3; ++m) m4[((i * 3 + j) * 3 + l) * 3 + m] += w * d[i] * d[j] * d[l] * d[m];
            }
      }
    first_[k] = m1;
    second_[k] = m2;
    third_[k] = m3;
    fourth_[k] = m4;
  }
}

double OrientationClasses::gnomonicRectangleArea(double u1, double u2, double v1, double v2) {
  auto F = [](double u, double v) { return std::atan(u * v / std::sqrt(1.0 + u * u + v * v)); };
  return F(u2, v2) - F(u1, v2) - F(u2, v1) + F(u1, v1);
}

OrientationClasses::Patch OrientationClasses::patch(std::size_t k) const {
  const int cells = 2 * divisions_;
  const int perFace = cells * cells;
  const int index = static_cast<int>(k);
  return {index / perFace, (index % perFace) / cells, index % cells};
}

Vec3 OrientationClasses::direction(int face, double alpha, double beta) {
  const int a = face / 2;
  Vec3 d;
  d[a] = face % 2 ? 1.0 : -1.0;
  d[(a + 1) % 3] = std::tan(alpha);
  d[(a + 2) % 3] = std::tan(beta);
  return d.normalized();
}

std::size_t OrientationClasses::classOf(const Vec3& n) const {
  // Directions whose first non-zero component is negative are classified as the mirror image of
  // −n: the class of −n is then exactly the mirror of the class of n, even for a direction on a
  // patch boundary (where the tie-break below is one-sided).
  const int lead = n[0] != 0.0 ? 0 : (n[1] != 0.0 ? 1 : 2);
  if (n[lead] < 0.0) return mirror(classOfCanonical(-n));
  return classOfCanonical(n);
}

std::size_t OrientationClasses::classOfCanonical(const Vec3& n) const {
  int a = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(n[i]) > std::abs(n[a])) a = i;
  const double m = std::abs(n[a]);
  const int face = 2 * a + (n[a] > 0.0 ? 1 : 0);
  const int cells = 2 * divisions_;
  const double h = (kPi / 2.0) / cells;
  auto cell = [&](double t) {
    const int c = static_cast<int>(std::floor((std::atan(t / m) + kQuarterPi) / h));
    return std::clamp(c, 0, cells - 1);
  };
  const int i = cell(n[(a + 1) % 3]), j = cell(n[(a + 2) % 3]);
  return static_cast<std::size_t>((face * cells + i) * cells + j);
}

std::size_t OrientationClasses::mirror(std::size_t k) const {
  const Patch p = patch(k);
  const int cells = 2 * divisions_;
  const int face = p.face ^ 1;  // same axis, opposite sign
  return static_cast<std::size_t>((face * cells + (cells - 1 - p.i)) * cells + (cells - 1 - p.j));
}

std::array<Vec3, 4> OrientationClasses::corners(std::size_t k) const {
  const Patch p = patch(k);
  const double h = (kPi / 2.0) / (2 * divisions_);
  const double a1 = -kQuarterPi + p.i * h, b1 = -kQuarterPi + p.j * h;
  std::array<Vec3, 4> c{direction(p.face, a1, b1), direction(p.face, a1 + h, b1),
                        direction(p.face, a1 + h, b1 + h), direction(p.face, a1, b1 + h)};
  // On the faces of negative sign the (α, β) frame is left-handed seen from outside.
  if ((c[1] - c[0]).cross(c[2] - c[0]).dot(centre_[k]) < 0.0) std::swap(c[1], c[3]);
  return c;
}

}  // namespace grainlab::lab

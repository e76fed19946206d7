#pragma once
// Triaxial ellipsoid shape (docs/physics.md §2, [O] ch. 3): semi-axes a >= b >= c along the body x, y,
// z axes, [O]'s shape parameters, mass and principal inertia, and the shape matrix
// X = Q diag(a^2, b^2, c^2) Q^T that every ellipsoid contact kernel works with. Pure functions.
#include <cmath>
#include <optional>
#include <string>

#include "core/types.hpp"

namespace grainlab::geometry {

// Symmetric 3x3 matrix by its six distinct entries: the shape matrices and their pencil
// G = (1 - lambda) X_A + lambda X_B are symmetric, and the contact solve inverts G by its
// adjugate, which is symmetric too (6 cofactors instead of 9, no pivoting).
struct Sym3 {
  double xx = 0, yy = 0, zz = 0, xy = 0, xz = 0, yz = 0;

  static Sym3 identity(double s = 1.0) { return {s, s, s, 0, 0, 0}; }
  Vec3 operator*(const Vec3& v) const {
    return {xx * v.x() + xy * v.y() + xz * v.z(), xy * v.x() + yy * v.y() + yz * v.z(),
            xz * v.x() + yz * v.y() + zz * v.z()};
  }
  // v^T S v
  double quadratic(const Vec3& v) const {
    return xx * v.x() * v.x() + yy * v.y() * v.y() + zz * v.z() * v.z() +
           2.0 * (xy * v.x() * v.y() + xz * v.x() * v.z() + yz * v.y() * v.z());
  }
  Sym3 operator+(const Sym3& o) const { return {xx + o.xx, yy + o.yy, zz + o.zz, xy + o.xy, xz + o.xz, yz + o.yz}; }
  Sym3 operator-(const Sym3& o) const { return {xx - o.xx, yy - o.yy, zz - o.zz, xy - o.xy, xz - o.xz, yz - o.yz}; }
  Sym3 operator*(double s) const { return {xx * s, yy * s, zz * s, xy * s, xz * s, yz * s}; }
  // Matrix of cofactors (= adjugate, symmetric): S^-1 = adjugate / det.
  Sym3 adjugate() const {
    return {yy * zz - yz * yz, xx * zz - xz * xz, xx * yy - xy * xy,
            xz * yz - xy * zz, xy * yz - xz * yy, xy * xz - xx * yz};
  }
  double determinant(const Sym3& adj) const { return xx * adj.xx + xy * adj.xy + xz * adj.xz; }
  Mat3 dense() const {
    Mat3 m;
    m << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return m;
  }
};

// Semi-axes from [O]'s parameters: equivalent radius r = (abc)^(1/3), elongation elr = b/a,
// flatness flr = c/b, so that a = r flr^(-1/3) elr^(-2/3), b = a elr, c = b flr.
inline Vec3 semiAxesFromOuadfel(double equivalentRadius, double elongation, double flatness) {
  const double a = equivalentRadius * std::pow(flatness, -1.0 / 3.0) * std::pow(elongation, -2.0 / 3.0);
  const double b = a * elongation;
  return {a, b, b * flatness};
}

inline double equivalentRadius(const Vec3& s) { return std::cbrt(s.x() * s.y() * s.z()); }
inline double elongationRatio(const Vec3& s) { return s.y() / s.x(); }  // elr = b/a <= 1
inline double flatnessRatio(const Vec3& s) { return s.z() / s.y(); }    // flr = c/b <= 1
// [O]'s eccentricity (a - b)/(a + b) = (1 - elr)/(1 + elr): 0.176 for elr = 0.7, 0.111 for 0.8.
// For prolate spheroids (b = c) it is docs/physics.md §2's (a - c)/(a + c).
inline double eccentricity(const Vec3& s) { return (s.x() - s.y()) / (s.x() + s.y()); }

inline double ellipsoidVolume(const Vec3& s) { return 4.0 / 3.0 * kPi * s.x() * s.y() * s.z(); }
inline double ellipsoidMass(const Vec3& s, double density) { return density * ellipsoidVolume(s); }
// Principal moments about the body x, y, z axes: m/5 (b^2 + c^2, a^2 + c^2, a^2 + b^2). [O]
// eq. 3.19 prints 2/5 instead of 1/5, which is twice too large (the sphere limit a = b = c must
// give 2/5 m r^2).
inline Vec3 ellipsoidPrincipalInertia(const Vec3& s, double mass) {
  const Vec3 s2 = s.cwiseProduct(s);
  return mass / 5.0 * Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());
}

// Radius of the bounding sphere (the broad phase's reach): the largest semi-axis.
inline double boundingRadius(const Vec3& s) { return s.maxCoeff(); }

// Shape matrix X = Q diag(a^2, b^2, c^2) Q^T of an ellipsoid with orientation q (body -> world):
// the ellipsoid is { y : (y - x)^T X^-1 (y - x) <= 1 } and its support distance along a unit u
// is sqrt(u^T X u). Computed once per particle and step and shared by all its contacts.
inline Sym3 shapeMatrix(const Vec3& semiAxes, const Quat& q) {
  const Mat3 r = q.toRotationMatrix();
  const Vec3 d = semiAxes.cwiseProduct(semiAxes);
  Sym3 x;
  x.xx = d.x() * r(0, 0) * r(0, 0) + d.y() * r(0, 1) * r(0, 1) + d.z() * r(0, 2) * r(0, 2);
  x.yy = d.x() * r(1, 0) * r(1, 0) + d.y() * r(1, 1) * r(1, 1) + d.z() * r(1, 2) * r(1, 2);
  x.zz = d.x() * r(2, 0) * r(2, 0) + d.y() * r(2, 1) * r(2, 1) + d.z() * r(2, 2) * r(2, 2);
  x.xy = d.x() * r(0, 0) * r(1, 0) + d.y() * r(0, 1) * r(1, 1) + d.z() * r(0, 2) * r(1, 2);
  x.xz = d.x() * r(0, 0) * r(2, 0) + d.y() * r(0, 1) * r(2, 1) + d.z() * r(0, 2) * r(2, 2);
  x.yz = d.x() * r(1, 0) * r(2, 0) + d.y() * r(1, 1) * r(2, 1) + d.z() * r(1, 2) * r(2, 2);
  return x;
}

// Half extents of the world-axis-aligned box around the ellipsoid (support distance along each
// world axis, sqrt(X_ii)): a tighter cell-list key than the bounding sphere.
inline Vec3 axisAlignedHalfExtents(const Sym3& x) { return {std::sqrt(x.xx), std::sqrt(x.yy), std::sqrt(x.zz)}; }

// What is wrong with a set of semi-axes, for the caller's one-line input error; nullopt when
// they are finite, positive and ordered a >= b >= c (the order the shape parameters and the
// inertia formula's axis labels assume).
inline std::optional<std::string> semiAxesProblem(const Vec3& s) {
  if (!s.allFinite() || !(s.minCoeff() > 0.0)) return "semi-axes must be finite and positive";
  if (!(s.x() >= s.y() && s.y() >= s.z())) return "semi-axes must be ordered a >= b >= c";
  return std::nullopt;
}

}  // namespace grainlab::geometry

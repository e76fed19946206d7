#pragma once
// Orientation classes: a near-uniform partition of the unit sphere into 24·N² patches, over which
// contact statistics are averaged ([O] ch. 2: averages per orientation class, 24 regions × N²
// patches, 384 classes for N = 4). Our partition is the equiangular cube-sphere: the sphere is
// projected on the six faces of the cube |x|∞ = 1; each face is cut into its four quadrants (the
// 24 regions) and each quadrant into N × N patches of equal angle α = atan(u), β = atan(v). Every
// patch is bounded by great circles, its solid angle is exact in closed form, the classes of n and
// −n are mirror images (central symmetry), and the largest patch is 1.41× the smallest for any N.
// docs/micromechanics.md §2 describes the scheme.
#include <array>
#include <cstddef>
#include <vector>

#include "core/types.hpp"

namespace grainlab::lab {

// Fully symmetric third- and fourth-order tensors stored as all their components, index
// (i·3 + j)·3 + k and ((i·3 + j)·3 + k)·3 + l.
using Tensor3 = std::array<double, 27>;
using Tensor4 = std::array<double, 81>;

class OrientationClasses {
 public:
  // `divisions` N ≥ 1 patches per quadrant edge (24·N² classes). Throws std::invalid_argument
  // for N < 1 or N > 64.
  explicit OrientationClasses(int divisions = 4);

  int divisions() const { return divisions_; }
  std::size_t size() const { return area_.size(); }

  // The class holding direction n (need not be normalised; must be non-zero). A direction on a
  // patch boundary goes to one of its patches, chosen so that classOf(−n) is always the mirror
  // image of classOf(n) (central symmetry holds for every direction, not only almost all).
  std::size_t classOf(const Vec3& n) const;

  // Solid angle [sr] of class k, from the closed form of a gnomonic rectangle (sum over all = 4π).
  double area(std::size_t k) const { return area_[k]; }
  // Unit direction at the centre of the patch (mid-angle in α and β).
  const Vec3& centre(std::size_t k) const { return centre_[k]; }
  // Moments of the patch: ∫_k n dΩ, ∫_k n⊗n dΩ, ∫_k n⊗n⊗n dΩ and ∫_k n⊗n⊗n⊗n dΩ, by 8 × 8
  // Gauss–Legendre quadrature in (α, β) (smooth integrand on a patch ≤ 45° wide: the area so
  // obtained matches the closed form to 1e-13 for N ≥ 1).
  const Vec3& firstMoment(std::size_t k) const { return first_[k]; }
  const Mat3& secondMoment(std::size_t k) const { return second_[k]; }
  const Tensor3& thirdMoment(std::size_t k) const { return third_[k]; }
  const Tensor4& fourthMoment(std::size_t k) const { return fourth_[k]; }
  // The four corners of the patch on the unit sphere, counter-clockwise seen from outside.
  std::array<Vec3, 4> corners(std::size_t k) const;

  // Closed-form solid angle of the gnomonic rectangle [u1, u2] × [v1, v2] on the face at distance 1:
  // Ω = F(u2,v2) − F(u1,v2) − F(u2,v1) + F(u1,v1), F(u,v) = atan(u·v / √(1 + u² + v²)).
  static double gnomonicRectangleArea(double u1, double u2, double v1, double v2);

 private:
  struct Patch {
    int face;          // 0..5: axis = face / 2, sign = face % 2 ? +1 : −1
    int i, j;          // angle cells along the face's two coordinates, 0..2N−1
  };
  Patch patch(std::size_t k) const;
  // classOf for a direction whose first non-zero component is positive: points on a patch
  // boundary go to the patch with the larger cell index (clamped at the face's outer edge); a
  // cube edge or corner goes to the face of the first largest |n_i|.
  std::size_t classOfCanonical(const Vec3& n) const;
  std::size_t mirror(std::size_t k) const;  // the class of the mirror patch (−n)
  // Direction of the face point with angles (alpha, beta) on `face`.
  static Vec3 direction(int face, double alpha, double beta);

  int divisions_;
  std::vector<double> area_;
  std::vector<Vec3> centre_, first_;
  std::vector<Mat3> second_;
  std::vector<Tensor3> third_;
  std::vector<Tensor4> fourth_;
};

}  // namespace grainlab::lab

#pragma once
// Contact-law slots (normal, tangential, rolling/twisting) as pure kernels over small structs
// (docs/physics.md §4). They know nothing of particle or contact storage; presets in models.hpp
// compose them. Convention: forces and moments are those of A on B; N points from A to B.
#include <cmath>

#include "core/types.hpp"

namespace grainlab::contact {

// Normal slot, linear and total (not incremental), no tension: Fn = Kn U N.
inline Vec3 normalLinear(double kn, double overlap, const Vec3& normal) {
  return (overlap > 0.0 ? kn * overlap : 0.0) * normal;
}

// The rotation that carries vectors attached to a contact (shear force, contact moment) along with
// the contact frame over one step: the rotation taking the previous normal onto the current one,
// then the spin of the pair about the normal by `twistAngle` [rad] (mean spin of the two bodies
// times dt, as in [O] eq. 3.10 and YADE's ScGeom). Built as a unit quaternion without trigonometry:
// the tilt quaternion (1 + n0.n1, n0 x n1) is exact; the twist uses (1, theta/2 n) normalised, a
// rotation by 2 atan(theta/2) = theta (1 - theta^2/12 + ...), exact to round-off for the ~1e-5 rad
// of a step. Being a rotation, it never changes the length of what it carries: a rigid rotation of
// a loaded contact leaves |Fs| and |M| as they were.
//
// The two quaternions are multiplied unnormalised and the product q = (w, u) is applied as
// R v = ((w^2 - u.u) v + 2 (u.v) u + 2 w u x v) / |q|^2, which is the rotation by q/|q|: one
// division per contact instead of two square roots and eight divisions (profile: the
// normalisations were the hottest instructions of the law).
struct FrameRotation {
  double w;
  Vec3 u;
  double invNorm2;  // 1 / |q|^2
  GRAINLAB_ALWAYS_INLINE Vec3 operator*(const Vec3& v) const {
    return ((w * w - u.squaredNorm()) * v + (2.0 * u.dot(v)) * u + (2.0 * w) * u.cross(v)) * invNorm2;
  }
};

GRAINLAB_ALWAYS_INLINE FrameRotation contactFrameRotation(const Vec3& prevNormal, const Vec3& normal, double twistAngle) {
  double tw = 1.0 + prevNormal.dot(normal);
  Vec3 tu = prevNormal.cross(normal);
  if (tw <= 1e-12) {  // normal reversed in one step: no defined tilt; carry nothing but the twist
    tw = 1.0;
    tu.setZero();
  }
  const Vec3 half = 0.5 * twistAngle * normal;  // twist quaternion (1, half)
  // (1, half) * (tw, tu) = (tw - half.tu, tu + tw half + half x tu)
  FrameRotation r{tw - half.dot(tu), tu + tw * half + half.cross(tu), 0.0};
  r.invNorm2 = 1.0 / (r.w * r.w + r.u.squaredNorm());
  return r;
}

struct SlipResult {
  Vec3 shearForce;
  double dissipation;  // energy dissipated by Coulomb slip in this step [J]
  bool sliding;
};

// Tangential slot: incremental elastic spring with Coulomb limit (docs/physics.md §4.1).
// `carriedShear` is the previous Fs already carried into the current contact frame, `dXs` the
// tangential displacement increment of B relative to A. Any normal component left by round-off is
// removed so Fs stays in the tangent plane.
GRAINLAB_ALWAYS_INLINE SlipResult tangentialCoulomb(const Vec3& carriedShear, double ks, const Vec3& dXs,
                                    const Vec3& normal, double normalForce, double tanFriction) {
  Vec3 trial = carriedShear - ks * dXs;
  trial -= normal * normal.dot(trial);
  const double limit = normalForce * tanFriction;
  SlipResult r{trial, 0.0, false};
  const double mag2 = trial.squaredNorm();  // the square root only for a sliding contact
  if (mag2 > limit * limit) {
    const double mag = std::sqrt(mag2);
    r.shearForce = mag > 0.0 ? Vec3(trial * (limit / mag)) : Vec3::Zero();
    r.sliding = true;
    // Work of the limit force over the slip (|Ft| - |Fs|)/ks, as YADE's plasticDissipation.
    r.dissipation = ks > 0.0 ? (mag - limit) * limit / ks : 0.0;
  }
  return r;
}

struct MomentResult {
  Vec3 moment;
  double dissipation;  // [J]
  bool yielding;
};

// Moment slot, elastic-perfectly-plastic: M <- carried M + Kr dTheta, |M| <= limit.
// The Kozicki–Donzé preset passes the full relative rotation (bending and twisting with the same
// Kr); the linear rolling preset passes only its bending part (see bendingPart).
GRAINLAB_ALWAYS_INLINE MomentResult momentElasticPlastic(const Vec3& carriedMoment, double kr, const Vec3& dTheta,
                                         double limit) {
  const Vec3 trial = carriedMoment + kr * dTheta;
  MomentResult r{trial, 0.0, false};
  const double mag2 = trial.squaredNorm();
  if (mag2 > limit * limit) {
    const double mag = std::sqrt(mag2);
    r.moment = mag > 0.0 ? Vec3(trial * (limit / mag)) : Vec3::Zero();
    r.yielding = true;
    r.dissipation = kr > 0.0 ? (mag - limit) * limit / kr : 0.0;  // limit moment x plastic rotation
  }
  return r;
}

// The part of a relative rotation perpendicular to the contact normal (bending / rolling).
inline Vec3 bendingPart(const Vec3& dTheta, const Vec3& normal) {
  return dTheta - normal * normal.dot(dTheta);
}

}  // namespace grainlab::contact

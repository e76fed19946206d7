#pragma once
// Contact-law slots (normal, tangential, rolling/twisting) as pure kernels over small structs
// (PHYSICS.md §3). They know nothing of particle or contact storage; presets in models.hpp
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
inline Quat contactFrameRotation(const Vec3& prevNormal, const Vec3& normal, double twistAngle) {
  const Vec3 axis = prevNormal.cross(normal);
  const double w = 1.0 + prevNormal.dot(normal);
  Quat tilt = w > 1e-12 ? Quat(w, axis.x(), axis.y(), axis.z()).normalized() : Quat::Identity();
  const Vec3 half = 0.5 * twistAngle * normal;
  const Quat twist = Quat(1.0, half.x(), half.y(), half.z()).normalized();
  return twist * tilt;
}

struct SlipResult {
  Vec3 shearForce;
  double dissipation;  // energy dissipated by Coulomb slip in this step [J]
  bool sliding;
};

// Tangential slot: incremental elastic spring with Coulomb limit (PHYSICS.md §3.1).
// `carriedShear` is the previous Fs already carried into the current contact frame, `dXs` the
// tangential displacement increment of B relative to A. Any normal component left by round-off is
// removed so Fs stays in the tangent plane.
inline SlipResult tangentialCoulomb(const Vec3& carriedShear, double ks, const Vec3& dXs,
                                    const Vec3& normal, double normalForce, double tanFriction) {
  Vec3 trial = carriedShear - ks * dXs;
  trial -= normal * normal.dot(trial);
  const double limit = normalForce * tanFriction;
  const double mag = trial.norm();
  SlipResult r{trial, 0.0, false};
  if (mag > limit) {
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
inline MomentResult momentElasticPlastic(const Vec3& carriedMoment, double kr, const Vec3& dTheta,
                                         double limit) {
  const Vec3 trial = carriedMoment + kr * dTheta;
  const double mag = trial.norm();
  MomentResult r{trial, 0.0, false};
  if (mag > limit) {
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

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

// Carries a vector attached to the contact (shear force, contact moment) along with the contact
// frame over one step: the exact rotation taking the previous normal onto the current one, then the
// spin of the pair about the normal by `twistAngle` [rad] (mean spin of the two bodies times dt,
// as in [O] eq. 3.10 and YADE's ScGeom). Both are exact rotations, so the length is unchanged —
// a rigid rotation of a loaded contact leaves |Fs| and |M| as they were.
inline Vec3 carryWithContact(const Vec3& v, const Vec3& prevNormal, const Vec3& normal,
                             double twistAngle) {
  const Vec3 axis = prevNormal.cross(normal);
  const double s = axis.norm();
  const double c = prevNormal.dot(normal);
  Vec3 out = v;
  if (s > 1e-300) {
    // Rodrigues with sin = s, cos = c about unit axis k: v c + (k x v) s + k (k.v)(1 - c).
    const Vec3 k = axis / s;
    out = v * c + k.cross(v) * s + k * (k.dot(v)) * (1.0 - c);
  }
  if (twistAngle != 0.0) {
    const double ct = std::cos(twistAngle), st = std::sin(twistAngle);
    out = out * ct + normal.cross(out) * st + normal * (normal.dot(out)) * (1.0 - ct);
  }
  return out;
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

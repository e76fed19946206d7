#pragma once
// Contact-model presets assembled from the slots of slots.hpp.
// Parameters that depend on the pair (stiffnesses, limits) come from `pairParams`; the law maps
// geometry x parameters x history to force and moment (YADE's Ip2 / Law2 split).
#include <cmath>
#include <variant>

#include "contact/slots.hpp"
#include "core/types.hpp"

namespace grainlab::contact {

// Kinematics of one contact over the current step, computed by the driver from the geometry.
struct ContactKinematics {
  Vec3 normal;            // A -> B, current
  Vec3 prevNormal;        // normal at the previous step (== normal for a new contact)
  double overlap;         // [m]
  Vec3 relativeVelocity;  // of B's material point at C relative to A's [m/s]
  Vec3 relativeSpin;      // omega_B - omega_A [rad/s]
  double meanSpinNormal;  // 0.5 (omega_A + omega_B) . N [rad/s]
  double dt;              // [s]
};

// History a contact keeps between steps.
struct ContactHistory {
  Vec3 shearForce = Vec3::Zero();
  Vec3 moment = Vec3::Zero();
  Vec3 prevNormal = Vec3::Zero();
  bool touching = false;
};

// What the law returns: force of A on B, and the contact moment accumulated from the rotation of
// B relative to A (B receives -moment, A receives +moment; PHYSICS.md §3.1).
struct ContactResponse {
  Vec3 force;
  Vec3 normalForce;
  Vec3 moment;
  double slipDissipation;
  double rollDissipation;
};

// Per-pair parameters, derived from the two bodies when the contact is evaluated.
struct PairParams {
  double kn;               // [N/m]
  double ks;               // [N/m]
  double kr;               // [N m/rad]
  double tanFriction;      // [-]
  double momentLimitArm;   // moment limit per unit |Fn| [m]
  bool twisting;           // whether the moment slot acts on twisting too
};

// Kozicki–Donzé contact with moments ([W] §3, PHYSICS.md §3.1):
// Kn = 2 Ec RA RB/(RA+RB), Ks = nu Kn, Kr = beta Ks RA RB, |M| <= eta (RA+RB)/2 |Fn|.
// The moment is incremental from (omega_B - omega_A) dt, like YADE's useIncrementalForm.
struct KozickiDonze {
  double young = 30e9;   // Ec [Pa]
  double poisson = 0.3;  // nu_c [-]
  double tanFriction = std::tan(degToRad(30.0));
  double beta = 0.15;    // [-]
  double eta = 1.0;      // [-]

  PairParams pairParams(double rA, double rB) const {
    const double kn = 2.0 * young * rA * rB / (rA + rB);
    const double ks = poisson * kn;
    return {kn, ks, beta * ks * rA * rB, tanFriction, eta * 0.5 * (rA + rB), true};
  }
  // A sphere of radius r against a rigid wall (R_B -> infinity): Kn = 2 Ec r, Ks = nu Kn,
  // Kr = beta Ks r^2. A smooth wall (tan = 0) carries no shear force and no moment; a frictional
  // wall limits the moment by eta r (the (RA+RB)/2 arm has no finite limit for a plane).
  PairParams wallParams(double r, double wallTanFriction) const {
    const double kn = 2.0 * young * r;
    const double ks = poisson * kn;
    const bool smooth = wallTanFriction <= 0.0;
    return {kn, ks, smooth ? 0.0 : beta * ks * r * r, wallTanFriction, smooth ? 0.0 : eta * r,
            true};
  }
  // Stiffest contact a sphere of radius r can have (against a wall), for the critical time step.
  double maxNormalStiffness(double r) const { return 2.0 * young * r; }
  double maxRotationalStiffness(double r) const {
    const double ks = poisson * 2.0 * young * r;
    return ks * r * r + beta * ks * r * r;  // shear spring at arm r plus the rolling spring
  }
};

// The law shared by the presets: normal, tangential (carried + Coulomb), moment (carried + limit).
inline ContactResponse applyLaw(const PairParams& p, const ContactKinematics& k, ContactHistory& h) {
  ContactResponse out;
  out.normalForce = normalLinear(p.kn, k.overlap, k.normal);
  const double fn = p.kn * k.overlap;
  const double twist = k.meanSpinNormal * k.dt;

  const Vec3 vt = k.relativeVelocity - k.normal * k.normal.dot(k.relativeVelocity);
  const Quat frame = contactFrameRotation(k.prevNormal, k.normal, twist);
  const Vec3 carriedShear = frame * h.shearForce;
  const SlipResult slip =
      tangentialCoulomb(carriedShear, p.ks, vt * k.dt, k.normal, fn, p.tanFriction);
  h.shearForce = slip.shearForce;
  out.slipDissipation = slip.dissipation;

  if (p.kr > 0.0) {
    Vec3 dTheta = k.relativeSpin * k.dt;
    if (!p.twisting) dTheta = bendingPart(dTheta, k.normal);
    Vec3 carriedMoment = frame * h.moment;
    if (!p.twisting) carriedMoment = bendingPart(carriedMoment, k.normal);
    const MomentResult m = momentElasticPlastic(carriedMoment, p.kr, dTheta, p.momentLimitArm * fn);
    h.moment = m.moment;
    out.rollDissipation = m.dissipation;
  } else {
    h.moment.setZero();
    out.rollDissipation = 0.0;
  }
  h.prevNormal = k.normal;
  out.force = out.normalForce + h.shearForce;
  out.moment = h.moment;
  return out;
}

// The set of contact models; resolved once per step with std::visit, never per contact.
using ContactModel = std::variant<KozickiDonze>;

}  // namespace grainlab::contact

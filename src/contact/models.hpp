#pragma once
// Contact-model presets assembled from the slots of slots.hpp.
// Parameters that depend on the pair (stiffnesses, limits) come from `pairParams`; the law maps
// geometry x parameters x history to force and moment (YADE's Ip2 / Law2 split).
#include <cmath>
#include <algorithm>

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

// History of a contact with an ellipsoid: the law's, plus the Perram–Wertheim parameter lambda of
// the last step (the warm start of the next solve) and the length of the contact's potential,
// frozen when the contact forms (geometry/ellipsoid_contacts.hpp, docs/ellipsoids.md).
struct EllipsoidHistory : ContactHistory {
  double lambda = 0.0;
  double potentialLength = 0.0;
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
  // YADE's variant (CohFrictPhys): bending and twisting each limited by momentLimitArm |Fn| on its
  // own, instead of the whole moment. Only for side-by-side comparisons with YADE.
  bool separateTwistLimit = false;
};

// How the rolling friction of a contact follows from its two grains' (model of [R]).
enum class CombineRule { Min, Mean, Harmonic };

inline double combineRollingFriction(CombineRule rule, double a, double b) {
  switch (rule) {
    case CombineRule::Min: return std::min(a, b);
    case CombineRule::Mean: return 0.5 * (a + b);
    case CombineRule::Harmonic: return a + b > 0.0 ? 2.0 * a * b / (a + b) : 0.0;
  }
  return std::min(a, b);
}

// Which rolling slot a sphere model uses. One enum for the whole run: the branch in pairParams is
// the same for every contact (perfectly predicted), no per-contact dispatch through pointers.
enum class RollingLaw {
  // Kozicki–Donzé ([W] §3, PHYSICS.md §3.1): Kr = beta Ks RA RB, full relative rotation (bending
  // and twisting), |M| <= eta (RA+RB)/2 |Fn|.
  KozickiDonze,
  // Linear rolling resistance ([R], PHYSICS.md §3.2): R = RA RB/(RA+RB), kr = Ks R^2, bending
  // only, |Mr| <= mu_r |Fn| R with mu_r combined from the two grains' values.
  Linear,
};

// Contact model for spheres: shared normal and tangential parts (Kn = 2 Ec RA RB/(RA+RB),
// Ks = nu Kn, Coulomb friction) and one of the rolling slots. Moments are incremental from
// (omega_B - omega_A) dt, like YADE's useIncrementalForm.
struct SphereContactModel {
  double young = 30e9;   // Ec [Pa]
  double poisson = 0.3;  // nu_c = Ks/Kn [-]
  double tanFriction = std::tan(degToRad(30.0));
  RollingLaw rolling = RollingLaw::KozickiDonze;
  double beta = 0.15;    // [-] (Kozicki–Donzé)
  double eta = 1.0;      // [-] (Kozicki–Donzé)
  CombineRule combine = CombineRule::Min;  // (Linear)
  // Kozicki–Donzé moment limit: [W]'s eta (RA+RB)/2 |Fn| on the whole moment (false), or YADE
  // 2023's eta min(RA,RB) |Fn| on bending and on twisting separately (true), so that a comparison
  // with YADE shows the engines' differences, not the laws'.
  bool yadeMomentLimit = false;
  // When > 0, every contact's normal stiffness Kn [N/m] (walls too), with Ks = poisson Kn: the
  // constant stiffness of [O] instead of Kn from the radii and Ec.
  double constantKn = 0.0;

  double normalStiffness(double rA, double rB) const {
    return constantKn > 0.0 ? constantKn : 2.0 * young * rA * rB / (rA + rB);
  }

  // muA, muB: the grains' rolling friction (Linear law only).
  PairParams pairParams(double rA, double rB, double muA = 0.0, double muB = 0.0) const {
    const double kn = normalStiffness(rA, rB);
    const double ks = poisson * kn;
    if (rolling == RollingLaw::Linear) {
      const double rBar = rA * rB / (rA + rB);
      return {kn, ks, ks * rBar * rBar, tanFriction, combineRollingFriction(combine, muA, muB) * rBar, false};
    }
    if (yadeMomentLimit) return {kn, ks, beta * ks * rA * rB, tanFriction, eta * std::min(rA, rB), true, true};
    return {kn, ks, beta * ks * rA * rB, tanFriction, eta * 0.5 * (rA + rB), true};
  }
  // A sphere of radius r against a rigid wall (R_B -> infinity): Kn = 2 Ec r, Ks = nu Kn. A smooth
  // wall (tan = 0, the default) carries no shear force and no moment. Against a frictional wall the
  // rolling stiffness is the R_B -> infinity limit (beta Ks r^2, or Ks r^2 with R = r) and the limit
  // arm eta r (the (RA+RB)/2 arm has no finite limit for a plane) or mu_r r.
  PairParams wallParams(double r, double wallTanFriction, double mu = 0.0) const {
    const double kn = maxNormalStiffness(r);
    const double ks = poisson * kn;
    if (wallTanFriction <= 0.0) return {kn, ks, 0.0, 0.0, 0.0, true};
    if (rolling == RollingLaw::Linear) return {kn, ks, ks * r * r, wallTanFriction, mu * r, false};
    return {kn, ks, beta * ks * r * r, wallTanFriction, eta * r, true};
  }
  // Stiffest contact a sphere of radius r can have (against a wall), for the critical time step.
  double maxNormalStiffness(double r) const { return constantKn > 0.0 ? constantKn : 2.0 * young * r; }
  double maxRotationalStiffness(double r) const {
    const double ks = constantKn > 0.0 ? poisson * constantKn : poisson * 2.0 * young * r;
    const double kr = rolling == RollingLaw::Linear ? ks * r * r : beta * ks * r * r;
    return ks * r * r + kr;  // shear spring at arm r plus the rolling spring
  }
};

// Forced inline into the contact loops: called out of line, its result struct went through the
// stack and was read back with wider loads than it was written with (store-forwarding stalls were
// the hottest samples of computeContacts in the profile).
#if defined(__GNUC__)
#define GRAINLAB_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define GRAINLAB_ALWAYS_INLINE inline
#endif

// The law shared by the presets: normal, tangential (carried + Coulomb), moment (carried + limit).
GRAINLAB_ALWAYS_INLINE ContactResponse applyLaw(const PairParams& p, const ContactKinematics& k, ContactHistory& h) {
  ContactResponse out;
  out.normalForce = normalLinear(p.kn, k.overlap, k.normal);
  const double fn = p.kn * k.overlap;
  const double twist = k.meanSpinNormal * k.dt;

  const Vec3 vt = k.relativeVelocity - k.normal * k.normal.dot(k.relativeVelocity);
  const FrameRotation frame = contactFrameRotation(k.prevNormal, k.normal, twist);
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
    if (p.separateTwistLimit) {
      const Vec3 twistM = k.normal * k.normal.dot(carriedMoment), twistD = k.normal * k.normal.dot(dTheta);
      const MomentResult b = momentElasticPlastic(carriedMoment - twistM, p.kr, dTheta - twistD, p.momentLimitArm * fn);
      const MomentResult t = momentElasticPlastic(twistM, p.kr, twistD, p.momentLimitArm * fn);
      h.moment = b.moment + t.moment;
      out.rollDissipation = b.dissipation + t.dissipation;
    } else {
      const MomentResult m = momentElasticPlastic(carriedMoment, p.kr, dTheta, p.momentLimitArm * fn);
      h.moment = m.moment;
      out.rollDissipation = m.dissipation;
    }
  } else {
    h.moment.setZero();
    out.rollDissipation = 0.0;
  }
  h.prevNormal = k.normal;
  out.force = out.normalForce + h.shearForce;
  out.moment = h.moment;
  return out;
}

// The law for a contact with no friction (tan mu = 0) and no moment spring (kr = 0): the normal
// spring alone. applyLaw gives the same force there (its Coulomb limit is 0, so whatever shear it
// carries is scaled to nothing, and the moment slot is off) at several times the cost.
GRAINLAB_ALWAYS_INLINE ContactResponse applyNormalLaw(const PairParams& p, const Vec3& normal, double overlap,
                                                      ContactHistory& h) {
  ContactResponse out;
  out.normalForce = normalLinear(p.kn, overlap, normal);
  out.force = out.normalForce;
  out.moment.setZero();
  out.slipDissipation = 0.0;
  out.rollDissipation = 0.0;
  h.shearForce.setZero();
  h.moment.setZero();
  h.prevNormal = normal;
  return out;
}

}  // namespace grainlab::contact

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
  // Overlap at the last step [m]: Hertz–Mindlin's unloading rescale of the carried shear force and
  // moment, and the stiffness its springs had when the contact opens (unused by the linear law).
  double overlap = 0.0;
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
// B relative to A (B receives -moment, A receives +moment; docs/physics.md §4.1).
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
  // Hertz–Mindlin (docs/physics.md §4.6): the coefficients of the overlap-dependent law; hertz = 0
  // for the linear law. kn, ks and kr above are the tangent stiffnesses at the current overlap once
  // SphereContactModel::resolve has been called (zero before).
  double hertz = 0.0;      // 4/3 E* sqrt(R*): Fn = hertz U^(3/2) [N/m^(3/2)]
  double mindlin = 0.0;    // 8 G* sqrt(R*): Ks = mindlin U^(1/2) [N/m^(3/2)]
  double rollRatio = 0.0;  // Kr / Ks [m^2]
  double damping = 0.0;    // 2 sqrt(5/6) |beta_e| sqrt(m*): normal dashpot c = damping sqrt(Sn) [kg^(1/2)]
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
  // Kozicki–Donzé ([W] §3, docs/physics.md §4.1): Kr = beta Ks RA RB, full relative rotation (bending
  // and twisting), |M| <= eta (RA+RB)/2 |Fn|.
  KozickiDonze,
  // Linear rolling resistance ([R], docs/physics.md §4.2): R = RA RB/(RA+RB), kr = Ks R^2, bending
  // only, |Mr| <= mu_r |Fn| R with mu_r combined from the two grains' values.
  Linear,
  // No contact moment (Hertz–Mindlin without a rolling slot).
  None,
};

// Which normal and tangential law: [W]'s linear springs, or Hertz–Mindlin (docs/physics.md §4.6).
enum class NormalLaw : std::uint8_t { Linear = 0, HertzMindlin = 1 };

// Hertz–Mindlin's stiffnesses for the critical time step are taken at least at this overlap, as a
// fraction of the grain radius (docs/physics.md §7): far above the overlaps of quartz at laboratory
// stresses. Soft grains at high stress overlap more; hertzReferenceOverlap() then gives the larger one.
inline constexpr double kHertzReferenceOverlap = 0.01;

// The overlap (as a fraction of r) of the most loaded contact a sample of grains of effective
// modulus E* can expect at a largest boundary stress sigma: Hertz's overlap under a force of
// 10 sigma (2r)^2 (force chains carry several times the mean force, and a deviator adds several
// times the confining pressure) between two spheres of radius r (R* = r/2):
// U/r = (30 sqrt(2) sigma / E*)^(2/3), and at least kHertzReferenceOverlap.
inline double hertzReferenceOverlap(double sigma, double effectiveYoung) {
  return std::max(kHertzReferenceOverlap, std::cbrt(std::pow(30.0 * std::sqrt(2.0) * sigma / effectiveYoung, 2.0)));
}

// The damping ratio of a normal dashpot that gives the coefficient of restitution e in a Hertzian
// collision: beta = ln e / sqrt(ln^2 e + pi^2) (Tsuji et al. 1992, as in LIGGGHTS and EDEM).
inline double restitutionDampingRatio(double e) {
  if (e >= 1.0) return 0.0;
  const double l = std::log(e);
  return l / std::sqrt(l * l + kPi * kPi);
}

// Contact model for spheres: shared normal and tangential parts (Kn = 2 Ec RA RB/(RA+RB),
// Ks = nu Kn, Coulomb friction) and one of the rolling slots. Moments are incremental from
// (omega_B - omega_A) dt, like YADE's useIncrementalForm.
//
// With law = HertzMindlin (docs/physics.md §4.6) `young` and `poisson` are the grain material's
// Young's modulus E and Poisson's ratio nu (E = 2 G (1 + nu) from contact.shear_modulus), the
// normal force is Hertz's 4/3 E* sqrt(R*) U^(3/2) and the tangential stiffness Mindlin's no-slip
// 8 G* sqrt(R* U), both with the effective moduli of two grains of that material; the rolling slot
// (none, Kozicki–Donzé or linear) takes Kr in proportion to that Ks.
struct SphereContactModel {
  double young = 30e9;   // Ec [Pa] (Hertz–Mindlin: E of the grain material)
  double poisson = 0.3;  // nu_c = Ks/Kn [-] (Hertz–Mindlin: nu of the grain material)
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
  NormalLaw law = NormalLaw::Linear;
  // Hertz–Mindlin's normal dashpot: the damping ratio ln e / sqrt(ln^2 e + pi^2) of the coefficient
  // of restitution e (restitutionDampingRatio); 0 for none.
  double restitutionBeta = 0.0;
  // Hertz–Mindlin: the run's largest boundary stress [Pa]; the stiffnesses for the critical time step
  // are taken at the overlap it gives with the current modulus (referenceOverlap()), so that a
  // softened preparation (smaller E, larger overlaps) gets its own, correct estimate.
  double referenceStress = 0.0;

  bool hertz() const { return law == NormalLaw::HertzMindlin; }
  double referenceOverlap() const { return hertzReferenceOverlap(referenceStress, effectiveYoung()); }
  // Effective moduli of two grains of the material: 1/E* = 2 (1 - nu^2)/E, 1/G* = 2 (2 - nu)/G.
  double effectiveYoung() const { return young / (2.0 * (1.0 - poisson * poisson)); }
  double effectiveShear() const { return young / (2.0 * (1.0 + poisson)) / (2.0 * (2.0 - poisson)); }

  double normalStiffness(double rA, double rB) const {
    return constantKn > 0.0 ? constantKn : 2.0 * young * rA * rB / (rA + rB);
  }

  // muA, muB: the grains' rolling friction (Linear law only). Hertz–Mindlin: the coefficients,
  // with kn = ks = kr = 0 until resolve() gives them at the overlap.
  PairParams pairParams(double rA, double rB, double muA = 0.0, double muB = 0.0) const {
    if (hertz()) return hertzParams(rA * rB / (rA + rB), rA, rB, muA, muB);
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
  // arm eta r (the (RA+RB)/2 arm has no finite limit for a plane) or mu_r r. Hertz–Mindlin: the
  // same limit, R* = r, with the wall of the grains' material.
  PairParams wallParams(double r, double wallTanFriction, double mu = 0.0) const {
    if (hertz()) {
      PairParams p = hertzParams(r, r, 0.0, mu, mu);
      if (wallTanFriction <= 0.0) {
        p.tanFriction = 0.0;
        p.rollRatio = 0.0;
        p.momentLimitArm = 0.0;
        p.twisting = true;
        p.separateTwistLimit = false;
      } else {
        p.tanFriction = wallTanFriction;
        if (rolling == RollingLaw::Linear) p.rollRatio = r * r, p.momentLimitArm = mu * r;
        else if (rolling == RollingLaw::KozickiDonze) p.rollRatio = beta * r * r, p.momentLimitArm = eta * r;
        p.separateTwistLimit = false;
      }
      return p;
    }
    const double kn = maxNormalStiffness(r);
    const double ks = poisson * kn;
    if (wallTanFriction <= 0.0) return {kn, ks, 0.0, 0.0, 0.0, true};
    if (rolling == RollingLaw::Linear) return {kn, ks, ks * r * r, wallTanFriction, mu * r, false};
    return {kn, ks, beta * ks * r * r, wallTanFriction, eta * r, true};
  }
  // Hertz–Mindlin: the tangent stiffnesses at `overlap` (dFn/dU = 3/2 hertz sqrt(U), Ks, Kr).
  // Nothing to do for the linear law.
  static void resolve(PairParams& p, double overlap) {
    if (p.hertz <= 0.0) return;
    const double root = std::sqrt(std::max(overlap, 0.0));
    p.kn = 1.5 * p.hertz * root;
    p.ks = p.mindlin * root;
    p.kr = p.rollRatio * p.ks;
  }
  // Normal force [N] and the energy of the normal spring [J] at `overlap` (params resolved).
  static double normalForce(const PairParams& p, double overlap) {
    if (overlap <= 0.0) return 0.0;
    return p.hertz > 0.0 ? p.hertz * overlap * std::sqrt(overlap) : p.kn * overlap;
  }
  // (Linear: kn U^2 / 2 as it stands, also for a contact still listed as touching whose overlap has
  // just turned negative; Hertz: 0 there.)
  static double normalEnergy(const PairParams& p, double overlap) {
    if (p.hertz > 0.0) return overlap > 0.0 ? 0.4 * p.hertz * overlap * overlap * std::sqrt(overlap) : 0.0;
    return 0.5 * p.kn * overlap * overlap;
  }
  // Stiffest contact a sphere of radius r can have (against a wall), for the critical time step.
  // Hertz–Mindlin: the tangent stiffness at the reference overlap referenceOverlap() r.
  double maxNormalStiffness(double r) const {
    if (hertz()) return 2.0 * effectiveYoung() * r * std::sqrt(referenceOverlap());
    return constantKn > 0.0 ? constantKn : 2.0 * young * r;
  }
  double maxShearStiffness(double r) const {
    if (hertz()) return 8.0 * effectiveShear() * r * std::sqrt(referenceOverlap());
    return poisson * maxNormalStiffness(r);
  }
  double maxRotationalStiffness(double r) const {
    const double ks = maxShearStiffness(r);
    const double kr = rolling == RollingLaw::None     ? 0.0
                      : rolling == RollingLaw::Linear ? ks * r * r
                                                      : beta * ks * r * r;
    return ks * r * r + kr;  // shear spring at arm r plus the rolling spring
  }
  // Hertz–Mindlin's dashpot coefficient for a pair of reduced mass mStar (0 without damping).
  double dampingFactor(double mStar) const {
    return restitutionBeta == 0.0 ? 0.0 : 2.0 * std::sqrt(5.0 / 6.0) * std::abs(restitutionBeta) * std::sqrt(mStar);
  }

 private:
  PairParams hertzParams(double rStar, double rA, double rB, double muA, double muB) const {
    PairParams p{0.0, 0.0, 0.0, tanFriction, 0.0, true};
    const double root = std::sqrt(rStar);
    p.hertz = 4.0 / 3.0 * effectiveYoung() * root;
    p.mindlin = 8.0 * effectiveShear() * root;
    if (rolling == RollingLaw::Linear) {
      p.rollRatio = rStar * rStar;
      p.momentLimitArm = combineRollingFriction(combine, muA, muB) * rStar;
      p.twisting = false;
    } else if (rolling == RollingLaw::KozickiDonze) {
      // rB = 0 marks a wall (R_B -> infinity): beta Ks r^2 and the arm eta r, set by wallParams.
      p.rollRatio = beta * rA * rB;
      p.momentLimitArm = yadeMomentLimit ? eta * std::min(rA, rB) : eta * 0.5 * (rA + rB);
      p.separateTwistLimit = yadeMomentLimit;
    }
    return p;
  }
};

// GRAINLAB_ALWAYS_INLINE: core/types.hpp.

// The tangential and moment slots shared by the laws: the carried shear force and moment are
// turned with the contact frame (and, when Rescale, multiplied by `scale`: Hertz–Mindlin's
// unloading), then the incremental springs with their Coulomb and moment limits at |Fn| = fn.
template <bool Rescale>
GRAINLAB_ALWAYS_INLINE void applyShearAndMoment(const PairParams& p, const ContactKinematics& k, ContactHistory& h,
                                                double fn, double scale, ContactResponse& out) {
  const double twist = k.meanSpinNormal * k.dt;

  const Vec3 vt = k.relativeVelocity - k.normal * k.normal.dot(k.relativeVelocity);
  const FrameRotation frame = contactFrameRotation(k.prevNormal, k.normal, twist);
  Vec3 carriedShear = frame * h.shearForce;
  if constexpr (Rescale) carriedShear *= scale;
  const SlipResult slip =
      tangentialCoulomb(carriedShear, p.ks, vt * k.dt, k.normal, fn, p.tanFriction);
  h.shearForce = slip.shearForce;
  out.slipDissipation = slip.dissipation;

  if (p.kr > 0.0) {
    Vec3 dTheta = k.relativeSpin * k.dt;
    if (!p.twisting) dTheta = bendingPart(dTheta, k.normal);
    Vec3 carriedMoment = frame * h.moment;
    if constexpr (Rescale) carriedMoment *= scale;
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
}

// The law shared by the linear presets: normal, tangential (carried + Coulomb), moment (carried + limit).
GRAINLAB_ALWAYS_INLINE ContactResponse applyLaw(const PairParams& p, const ContactKinematics& k, ContactHistory& h) {
  ContactResponse out;
  out.normalForce = normalLinear(p.kn, k.overlap, k.normal);
  const double fn = p.kn * k.overlap;
  applyShearAndMoment<false>(p, k, h, fn, 1.0, out);
  return out;
}

// Hertz–Mindlin (docs/physics.md §4.6), with `p` resolved at k.overlap. Normal: Hertz's
// hertz U^(3/2) plus the dashpot -c vn, c = damping sqrt(Sn), Sn = dFn/dU (Tsuji et al. 1992), the
// sum never tensile. Tangential: Mindlin's no-slip stiffness Ks = 8 G* sqrt(R* U) on the increment
// of tangential displacement (the incremental form of PFC and YADE), and when the overlap falls
// the carried force is scaled by Ks(U)/Ks(U_prev) = sqrt(U/U_prev) (Walton's unloading rule, LAMMPS'
// mindlin_rescale/force): a normal load cycle at fixed tangential displacement then neither creates
// nor keeps spurious tangential force. The moment spring (Kr proportional to Ks) is carried the
// same way. Coulomb and moment limits use the total normal force. `viscous` receives the energy
// the dashpot dissipated over the step [J].
GRAINLAB_ALWAYS_INLINE ContactResponse applyHertzMindlin(const PairParams& p, const ContactKinematics& k,
                                                         ContactHistory& h, double& viscous) {
  ContactResponse out;
  const double u = k.overlap;
  const double elastic = p.hertz * u * std::sqrt(u);
  double fn = elastic;
  viscous = 0.0;
  if (p.damping > 0.0) {
    const double vn = k.normal.dot(k.relativeVelocity);  // > 0 when the grains separate
    fn = std::max(0.0, elastic - p.damping * std::sqrt(p.kn) * vn);
    viscous = -(fn - elastic) * vn * k.dt;
  }
  out.normalForce = fn * k.normal;
  const double scale = h.overlap > u ? std::sqrt(u / h.overlap) : 1.0;
  // The springs' energy |F|^2/2K that the change of stiffness takes away with the force held
  // (loading) or scaled with K (unloading): never negative; booked as slip (moment: rolling)
  // dissipation, so that the energy ledger closes (the incremental law is not conservative there).
  double shearLoss = 0.0, momentLoss = 0.0;
  if (h.overlap > 0.0) {
    const double ksOld = p.mindlin * std::sqrt(h.overlap);
    if (ksOld > 0.0 && p.ks > 0.0) shearLoss = 0.5 * h.shearForce.squaredNorm() * (1.0 / ksOld - scale * scale / p.ks);
    const double krOld = p.rollRatio * ksOld;
    if (krOld > 0.0 && p.kr > 0.0) momentLoss = 0.5 * h.moment.squaredNorm() * (1.0 / krOld - scale * scale / p.kr);
  }
  h.overlap = u;
  applyShearAndMoment<true>(p, k, h, fn, scale, out);
  out.slipDissipation += shearLoss;
  out.rollDissipation += momentLoss;
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

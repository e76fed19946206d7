#pragma once
// Micromechanical analysis of a contact network (docs/physics.md §11, [O] ch. 2 and 6): coordination
// and rattlers, fabric, orientation-class averages of forces and branch vectors, their second-order
// (optionally fourth-order) anisotropies, and the stress rebuilt from them (stress–force–fabric).
// Pure functions over a plain description of the network, independent of how the engine stores
// it; every definition, with its reference, is in docs/micromechanics.md.
//
// Conventions: n points from A to B; `force` is the force exerted by A on B (for a wall contact:
// by the particle on the wall); stresses are compression positive, σ_ij = (1/V) Σ f_i l_j.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "lab/orientation_classes.hpp"

namespace grainlab::lab {

struct MicroParticle {
  enum class Shape { Sphere, Ellipsoid };
  std::int64_t id = 0;          // any unique non-negative integer
  Vec3 centre = Vec3::Zero();   // [m]
  Shape shape = Shape::Sphere;
  double radius = 0.0;          // sphere radius [m]
  Vec3 semiAxes = Vec3::Zero(); // ellipsoid a ≥ b ≥ c [m]
  Vec3 longAxis = Vec3::UnitZ(); // ellipsoid: unit vector along the semi-axis a
  bool frictionless = false;    // rattler rule: 4 contacts needed instead of 2
};

struct MicroContact {
  std::int64_t a = 0;           // particle id of A
  std::int64_t b = 0;           // particle id of B, or the wall index when `wall`
  bool wall = false;
  Vec3 normal = Vec3::UnitZ();  // unit, from A to B
  Vec3 force = Vec3::Zero();    // force of A on B, normal + tangential [N]
  Vec3 branchA = Vec3::Zero();  // contact point − centre of A [m]
  Vec3 branchB = Vec3::Zero();  // contact point − centre of B [m] (unused for a wall)
};

struct MicroNetwork {
  std::vector<MicroParticle> particles;
  std::vector<MicroContact> contacts;  // touching contacts only
  double volume = 0.0;                 // V of the sample (box or cell) [m³]
  std::optional<Mat3> measuredStress;  // e.g. the wall stresses, compression positive [Pa]
};

struct MicroOptions {
  int classDivisions = 4;    // N: 24·N² orientation classes
  bool fourthOrder = false;  // also the fourth-order terms of E(n) and of the mean normal force
  int axialAxis = 2;         // axis of σ1 for q = σ_aa − (σ_bb + σ_cc)/2 (z)
};

// Coordination (§1 of docs/micromechanics.md). Z counts particle–particle contacts only; the
// rattler rule counts wall contacts too (a wall is never removed).
struct Coordination {
  std::size_t particles = 0, particleContacts = 0, wallContacts = 0;
  double Z = 0.0;                      // 2·Nc/Np
  std::optional<double> Zmech;         // 2·Nc/Np over the non-rattlers; null when all are rattlers
  std::size_t rattlers = 0;
  double rattlerFraction = 0.0;
  std::vector<std::size_t> histogram;  // histogram[k]: particles with k particle–particle contacts
  std::vector<bool> isRattler;         // per particle, in the order of MicroNetwork::particles
};

// Per orientation class; each contact is counted in the class of n and (with its tangential
// force and branch reversed) in the class of −n, so the statistics are centrally symmetric.
struct ClassAverages {
  std::vector<std::size_t> count;          // 2·Nc entries in all
  std::vector<double> meanNormalForce;     // f̄ⁿ [N]; NaN in an empty class
  std::vector<Vec3> meanTangentialForce;   // f̄ᵗ [N]
  std::vector<double> meanBranchNormal;    // l̄ⁿ [m]
  std::vector<Vec3> meanBranchTangential;  // l̄ᵗ [m]
};

// A second-order anisotropy tensor with its scalar measures.
struct Anisotropy {
  Mat3 tensor = Mat3::Zero();        // symmetric, traceless
  double magnitude = 0.0;            // sign(a : s)·√(3/2 a:a), s the deviator of the reference stress
  Vec3 principal = Vec3::Zero();     // eigenvalues, largest first
};

struct MicroAnalysis {
  Coordination coordination;
  Mat3 fabric = Mat3::Zero();        // R = <n ⊗ n> over particle–particle contacts
  // The rest is null when there is no particle–particle contact (nothing to measure).
  std::optional<Anisotropy> ar, an, at, av, atau;  // contact normals, normal and tangential
                                                   // force, branch length and branch tangential
  std::optional<Anisotropy> aE;      // long axes of the ellipsoids; null without ellipsoids
  std::optional<Tensor4> ar4, an4;   // fourth-order terms (MicroOptions::fourthOrder)
  std::optional<double> f0, l0;      // mean normal force and branch length over orientations
  std::size_t emptyClasses = 0;
  ClassAverages classes;
  // Stresses [Pa], compression positive.
  Mat3 stressParticleContacts = Mat3::Zero();  // (1/V) Σ f⊗l over particle–particle contacts
  Mat3 stressAllContacts = Mat3::Zero();       // + wall contacts, f⊗(contact − centre)
  std::optional<Mat3> stressMeasured;
  std::optional<Mat3> stressSffLinear;  // first order in the anisotropies
  std::optional<Mat3> stressSff;        // the whole product of the truncated densities
  // q/p with q = σ_aa − (σ_bb + σ_cc)/2 along MicroOptions::axialAxis, p = tr σ / 3.
  std::optional<double> qOverPMeasured, qOverPContacts, qOverPParticleContacts, qOverPSff, qOverPSffLinear;
  // ‖σ_sff − σ_pp‖ / ‖σ_pp‖ (Frobenius, σ_pp over the same contacts) and the same against the
  // measured stress.
  std::optional<double> sffError, sffErrorMeasured;
  bool nonSpherical = false;
};

// Mechanical coordination by repeated removal of rattlers (docs/micromechanics.md §1).
Coordination coordination(const MicroNetwork& network);

// The analysis; holds the orientation classes so that repeated calls do not rebuild them.
class MicroAnalyzer {
 public:
  explicit MicroAnalyzer(MicroOptions options = {});
  // Throws std::invalid_argument for a contact naming an unknown particle or V ≤ 0.
  MicroAnalysis analyse(const MicroNetwork& network) const;
  const OrientationClasses& classes() const { return classes_; }
  const MicroOptions& options() const { return options_; }

 private:
  MicroOptions options_;
  OrientationClasses classes_;
};

// Parameters of the stress–force–fabric relation: σ_ij = m_v·f0·l0·(1/4π)∫ E(n)·F̂_i(n)·L̂_j(n) dΩ
// with 4π·E = 1 + a^r:nn (+ A^r::nnnn), F̂ = (1 + a^n:nn (+ A^n::nnnn))·n + a^t·n − (a^t:nn)·n,
// L̂ = (1 + a^v:nn)·n + a^τ·n − (a^τ:nn)·n (docs/micromechanics.md §4).
struct SffTerms {
  double mv = 0.0, f0 = 0.0, l0 = 0.0;  // contacts per volume [1/m³], [N], [m]
  Mat3 ar = Mat3::Zero(), an = Mat3::Zero(), at = Mat3::Zero(), av = Mat3::Zero(), atau = Mat3::Zero();
  std::optional<Tensor4> ar4, an4;
};
// The integral of the product of the truncated densities, evaluated exactly (every cross term).
Mat3 sffStress(const SffTerms& t);
// First order: σ0·(δ + 2/5·(a^r + a^n + a^v) + 3/5·(a^t + a^τ)), σ0 = m_v f0 l0 / 3.
Mat3 sffStressLinear(const SffTerms& t);

// Tensor helpers (exposed for tests).
Anisotropy anisotropyOf(const Mat3& a, const Mat3& referenceStress);
// Deviatoric (fully traceless) part of a fully symmetric fourth-order tensor.
Tensor4 deviator4(const Tensor4& t);
double contract4(const Tensor4& t, const Vec3& n);  // t_ijkl n_i n_j n_k n_l
double norm4(const Tensor4& t);                      // √(t::t)
// q/p along `axis`: (σ_aa − (σ_bb + σ_cc)/2) / (tr σ / 3); null when p ≤ 0.
std::optional<double> qOverP(const Mat3& stress, int axis);

// Time-series columns (README, docs/interface.md): which set a run uses is fixed by whether the
// assembly has ellipsoids and whether the fourth-order terms are on.
struct MicroColumnSet {
  bool nonSpherical = false;
  bool fourthOrder = false;
};
std::vector<std::string> microColumnNames(const MicroColumnSet& set);
// Values in the order of microColumnNames; null where a value could not be measured.
std::vector<std::optional<double>> microRowValues(const MicroAnalysis& m, const MicroColumnSet& set);

}  // namespace grainlab::lab

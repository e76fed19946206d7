#pragma once
// Laboratory protocols in a box of rigid walls (LAB.md tests 1–3): sample preparation with a
// preparation friction (searched to meet a target e0), isotropic compression to the confining
// pressure, and drained triaxial compression.
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "core/simulation.hpp"
#include "lab/grading.hpp"
#include "lab/kinematics.hpp"
#include "lab/run_config.hpp"

namespace grainlab::lab {

// Called during long phases: phase name, fraction done in [0, 1], steps so far in the phase.
using ProgressFn = std::function<void(const std::string& phase, double fraction, long steps)>;
// Called for snapshots (e.g. VTK) during shearing, with the current axial strain.
using SnapshotFn = std::function<void(const Simulation& sim, double eps1)>;
class Laboratory;
// Called to write a checkpoint (between steps, during shearing).
using CheckpointFn = std::function<void(const Laboratory& lab)>;

// One row of the time series (PHYSICS.md §0 signs: compression positive, eps_v > 0 contraction).
struct Record {
  long step = 0;
  double time = 0.0;
  double eps1 = 0.0, eps2 = 0.0, eps3 = 0.0, epsV = 0.0;
  double sigma1 = 0.0, sigma2 = 0.0, sigma3 = 0.0;  // wall stresses: axial z, lateral x, lateral y
  double q = 0.0, p = 0.0, e = 0.0, phiDeg = 0.0;
  double coordination = 0.0, unbalanced = 0.0, inertialNumber = 0.0;
  double sigma1Contact = 0.0, sigma2Contact = 0.0, sigma3Contact = 0.0;
  double rotationMeanDeg = 0.0, rotationBandMeanDeg = 0.0, bandFraction = 0.0;
  double kinetic = 0.0, elastic = 0.0, workBoundary = 0.0, dissipSlip = 0.0, dissipRoll = 0.0,
         dissipDamping = 0.0;
};

struct EquilibriumState {
  Vec3 wallStress;   // [Pa]
  Mat3 contactStress;
  double unbalanced;
  double voidRatio;
};

struct PreparationResult {
  double e0 = 0.0;                 // reached
  double prepFrictionDeg = 0.0;    // used for the final sample
  std::vector<std::pair<double, double>> search;  // (mu_prep deg, e reached) per trial
  long steps = 0;
  GradingStats grading{};
  EquilibriumState state{};
};

struct ShearResult {
  std::vector<Record> records;
  double strainRate = 0.0;        // [1/s]
  double inertialNumber = 0.0;    // eps_dot d50 sqrt(rho/p)
  double maxLateralDeviation = 0.0;  // max |sigma_lat - p|/p over the shear phase
  long steps = 0;
};

class Laboratory {
 public:
  Laboratory(const RunConfig& config, ProgressFn progress = {});

  // Draws the grading, places particles loosely, compacts to the confining pressure with the
  // preparation friction (searched when not given) and re-equilibrates with friction restored.
  PreparationResult prepare();
  // Starts from a given packing (particles and walls already in `packed`): equilibrium at full
  // stiffness and friction at the confining pressure, no compaction and no e0 search.
  PreparationResult adoptPacking(Simulation packed);
  // Drained triaxial compression of the prepared sample (platens at constant speed, lateral walls
  // servo-controlled at sigma3 = p) to the final axial strain: beginShear() then continueShear().
  ShearResult shear();
  void beginShear();
  // Runs (or, after loadState, resumes) the shearing loop to the final axial strain.
  ShearResult continueShear();
  bool shearStarted() const { return shear_.started; }

  // Checkpoints every `everyStrain` of axial strain during shearing.
  void onCheckpoint(CheckpointFn fn, double everyStrain) {
    checkpoint_ = std::move(fn);
    checkpointEvery_ = everyStrain;
  }
  // Exact binary state (engine and shearing protocol) for checkpoints.
  void saveState(std::ostream& out) const;
  void loadState(std::istream& in);

  // Snapshots every `everyStrain` of axial strain during shearing (and at its start and end).
  void onSnapshot(SnapshotFn fn, double everyStrain) {
    snapshot_ = std::move(fn);
    snapshotEvery_ = everyStrain;
  }

  Simulation& simulation() { return sim_; }
  const Simulation& simulation() const { return sim_; }
  // Consolidates to an isotropic stress p until stress and unbalanced force meet the tolerances.
  long consolidate(double pressure, const std::string& phase);
  EquilibriumState equilibriumState() const;
  // Grain displacement, rotation, local strain and shear band since the start of shearing; the
  // neighbourhood of the local strain is kNeighbourhoodDiameters * d50.
  GrainKinematics currentKinematics() const;
  static constexpr double kNeighbourhoodDiameters = 2.0;
  static constexpr double kPlatenRampIntegralTimes = 40.0;
  static constexpr double kAutoInertialNumber = 0.98e-3;
  // A record of the current state; the wall stresses are meanStress when given (the mean over the
  // recording interval, as a load cell reports it), else the instantaneous ones.
  Record measure(double h0, double v0, const Vec3& l0, double strainRate,
                 const Vec3* meanStress = nullptr) const;

 private:
  RunConfig config_;
  ProgressFn progress_;
  SnapshotFn snapshot_;
  double snapshotEvery_ = 0.0;
  CheckpointFn checkpoint_;
  double checkpointEvery_ = 0.0;
  // Where the shearing loop stands (all of it goes into a checkpoint).
  struct ShearState {
    bool started = false;
    double h0 = 0.0, v0 = 0.0;
    Vec3 l0 = Vec3::Zero();
    double platenSpeed = 0.0;
    long rampSteps = 1, startStep = 0;
    double nextRecord = 0.0, nextSnapshot = 0.0, nextCheckpoint = 0.0;
    // Wall stresses summed over the steps since the last record: a record carries their mean.
    Vec3 stressSum = Vec3::Zero();
    long stressSamples = 0;
    ShearResult result;
  };
  ShearState shear_;
  Simulation sim_;
  double d50_ = 0.0;
  std::optional<Vec3> shearReference_;  // box lengths at the start of shearing
  void setFriction(double deg) { sim_.model.tanFriction = std::tan(degToRad(deg)); }
  long rampStiffness();
  double compactWithFriction(const Simulation& loose, double muDeg, Simulation& out, long& steps);
};

// Gives every grain its rolling friction (contact.model = "rolling-linear"): the uniform
// contact.rolling_friction, or c psi^k with psi drawn from contact.sphericity (seeded).
void assignRollingFriction(const RunConfig& config, Particles& particles);

// Sets up the contact model, damping, servo and time step of a simulation from the config.
// Throws InputError when an explicit solver.dt exceeds the critical time step (unless forced).
void configureSolver(const RunConfig& config, Simulation& sim);

}  // namespace grainlab::lab

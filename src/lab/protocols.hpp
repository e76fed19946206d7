#pragma once
// Laboratory protocols (docs/laboratory.md §1–2) in a box of rigid walls or a periodic cell: sample
// preparation (compaction with a preparation friction searched to meet a target e0, or frictionless
// radius growth), isotropic consolidation, and the shearing tests: drained triaxial compression,
// compression at constant mean stress, true triaxial at constant b, and simple shear at constant
// normal stress (cell only). Each protocol assembles a Pipeline (core/pipeline.hpp): the engine's
// stages plus its own drives, recorders, snapshots, checkpoints and stop condition.
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "core/pipeline.hpp"
#include "core/simulation.hpp"
#include "lab/grading.hpp"
#include "lab/grain_records.hpp"
#include "lab/kinematics.hpp"
#include "lab/shear_band.hpp"
#include "lab/micromechanics.hpp"
#include "lab/moduli.hpp"
#include "lab/protocol/shear_protocol.hpp"
#include "lab/run_config.hpp"

namespace grainlab::lab {

// Called during long phases: phase name, fraction done in [0, 1], steps so far in the phase.
using ProgressFn = std::function<void(const std::string& phase, double fraction, long steps)>;
// Called for snapshots (e.g. VTK) during shearing, with the current strain (axial, or shear strain
// in simple shear).
using SnapshotFn = std::function<void(const Simulation& sim, double strain)>;
class Laboratory;
// Called to write a checkpoint (between steps, during shearing).
using CheckpointFn = std::function<void(const Laboratory& lab)>;

// One row of the time series (docs/physics.md §1 signs: compression positive, eps_v > 0 contraction).
struct Record {
  long step = 0;
  double time = 0.0;
  double eps1 = 0.0, eps2 = 0.0, eps3 = 0.0, epsV = 0.0;
  double sigma1 = 0.0, sigma2 = 0.0, sigma3 = 0.0;  // boundary stresses: axial z, lateral x, lateral y
  double q = 0.0, p = 0.0, e = 0.0, phiDeg = 0.0;
  double coordination = 0.0, unbalanced = 0.0, inertialNumber = 0.0;
  double sigma1Contact = 0.0, sigma2Contact = 0.0, sigma3Contact = 0.0;
  // The boundary's stress at the record's step (sigma1..3 are means over the recording interval)
  // and the part of it the contacts do not carry (lab::unbalancedStress, zero in a cell): the
  // summary's boundary-contact stress gap is explained by these two (not written to timeseries.csv).
  double sigma1Now = 0.0, sigma2Now = 0.0, sigma3Now = 0.0;
  double sigma1Unbalanced = 0.0, sigma2Unbalanced = 0.0, sigma3Unbalanced = 0.0;
  double rotationMeanDeg = 0.0, rotationBandMeanDeg = 0.0, bandFraction = 0.0;
  double rotationOutsideMeanDeg = 0.0, rotationBandStdDeg = 0.0, rotationOutsideStdDeg = 0.0;  // NaN: not measured
  // The shear band's plane from the strain increment of the window that closes at this record
  // (output.band_strain_window; bandMeasured 1 there, 0 at the records in between): NaN where no
  // band is found or none was looked for.
  double bandInclinationDeg = 0.0, bandThicknessD50 = 0.0;
  double bandMeasured = 0.0;
  double kinetic = 0.0, elastic = 0.0, workBoundary = 0.0, dissipSlip = 0.0, dissipRoll = 0.0,
         dissipDamping = 0.0;
  double workGravity = 0.0;  // work of gravity on the particles [J] (sample.gravity)
  // Periodic cell: logarithmic axial strain -ln(H_zz/H0_zz), and the skew part of the contact
  // stress relative to p (a check: zero without contact moments at equilibrium).
  double eps1Log = 0.0, stressSkew = 0.0;
  // Simple shear: shear strain gamma = H_xz / H_zz and the shear stress the sample opposes to it,
  // tau = -sigma_xz [Pa] (sigma compression positive: a shear with dx/dt = gamma_dot z loads the
  // contacts along (-1, 0, 1), so sigma_xz < 0).
  double gamma = 0.0, tau = 0.0;
  // True triaxial: b = (sigma2 - sigma3)/(sigma1 - sigma3) of the recorded stresses (NaN while
  // sigma1 = sigma3, written as an empty field).
  double b = 0.0;
  // Micromechanics (lab/micromechanics.hpp), the columns microColumnNames() lists, NaN where a value
  // could not be measured (written as an empty field, null).
  static constexpr std::size_t kMicroColumns = 40;
  std::array<double, kMicroColumns> micro{};
  // Energy balance ([W] §4.9, docs/physics.md §10) since the start of shearing, as a fraction of the
  // external work: (W - dE_elastic - dE_kinetic - D_slip - D_roll - D_damping) / W; NaN while W = 0.
  double energyResidual = 0.0;
  // Triaxial unload–reload loops (test.unload_reload_at): 0 monotonic loading, 1 unloading,
  // 2 reloading, 3 at rest at the reversal strain before the unload (test.loop_rest).
  long loopPhase = 0;
  // Undrained tests: excess pore pressure u [Pa] (ShearProtocol::excessPorePressure); p, q and
  // sigma1..3 stay the effective stresses the grains carry.
  double u = 0.0;
  // Cyclic tests: cycles completed (in halves); oedometer and cyclic: +1 loading, -1 unloading.
  double cycle = 0.0;
  long loadDirection = 1;
  // Stress path: the progress variable s, and the point the path runs to (1-based; the number of
  // points once the path is done).
  double pathS = 0.0;
  long pathSegment = 0;
};

struct EquilibriumState {
  Vec3 boundaryStress;   // [Pa]
  Mat3 contactStress;
  double unbalanced;
  double voidRatio;
  double coordination;
};

// One stage of the [O] growth of grain shape (after its relaxation at constant p).
struct GrowthStage {
  double eccentricity = 0.0;     // (a - b)/(a + b) of the grown grains
  double coordination = 0.0;     // Z, contacts per particle
  double coordinationStd = 0.0;  // spread of the particles' contact counts (standard deviation)
  double packingFraction = 0.0;  // solid volume / cell volume
};

// sample.method = "deposition": the rain and settling, before the platen and the servos take over.
struct DepositionReport {
  double dropHeight = 0.0;          // [m] free fall of the cloud's lowest grains
  double cloudHeight = 0.0;         // [m]
  double cloudSolidFraction = 0.0;  // of the cloud at release
  double width = 0.0;               // [m] side of the square footprint
  double bedHeight = 0.0;           // [m] highest grain top after settling
  double settledVoidRatio = 0.0;    // of the settled bed (box footprint x bed height), before consolidation
  double settledCoordination = 0.0; // Z of the settled bed
  std::optional<double> settledFabricZz;  // a_r_zz = 15/2 (R_zz - 1/3) of the settled bed (null: no contact)
  double gravityWork = 0.0;         // [J] work of gravity during the rain and settling
  long steps = 0;
};

// sample.method = "under-compaction": the layers and their tamping, before the platen and the servos
// take over.
struct UnderCompactionReport {
  int layers = 0;
  double underCompaction = 0.0;       // U of the bottom layer
  double targetVoidRatio = 0.0;       // e0: the density every layer is meant to end at
  double width = 0.0;                 // [m] side of the square footprint
  std::vector<double> targetHeights;  // [m] platen height after tamping layer k (the sample built so far)
  std::vector<double> tampedVoidRatio;  // e of the sample built so far, after tamping layer k and relaxing
  std::vector<double> tamperStress;   // [Pa] the platen's stress when it stopped, per layer
  std::vector<bool> tamperReached;    // per layer: the platen reached its height (false: it stalled at p)
  double tamperSpeed = 0.0;           // [m/s] of the last layer
  // After the last layer (before consolidation): e, Z, a_r_zz, and e of `layers` horizontal slices of
  // equal thickness from the floor to the platen (the void ratio profile).
  double voidRatio = 0.0;
  double coordination = 0.0;
  std::optional<double> fabricZz;
  std::vector<double> voidRatioProfile;
  // The same profile after consolidation to p and the final equilibrium (what the test starts from).
  std::vector<double> preparedProfile;
  double gravityWork = 0.0;  // [J]
  long steps = 0;
};

struct PreparationResult {
  double e0 = 0.0;                          // reached
  std::vector<GrowthStage> growth;          // the shape growth curve (ellipsoids), stage 0 = spheres
  std::optional<double> prepFrictionDeg;    // used for the final sample (none for a packing file)
  std::vector<std::pair<double, double>> search;  // (mu_prep deg, e reached) per trial
  long steps = 0;
  GradingStats grading{};
  EquilibriumState state{};
  // Coordination of the prepared sample (docs/micromechanics.md §1): Z over every particle, Z_mech
  // over the non-rattlers (null when every grain is a rattler).
  Coordination coordination{};
  std::optional<DepositionReport> deposition;  // sample.method = "deposition"
  std::optional<UnderCompactionReport> underCompaction;  // sample.method = "under-compaction"
};

struct ShearResult {
  std::vector<Record> records;
  double strainRate = 0.0;        // [1/s] axial (or shear, in simple shear)
  double inertialNumber = 0.0;    // rate d50 sqrt(rho/p)
  double maxLateralDeviation = 0.0;     // max |sigma_lat - target|/p, lateral stress = mean of two walls
  double maxSingleWallDeviation = 0.0;  // the same for the worst single lateral wall (wall box)
  long steps = 0;
  // test.rate_follows_pressure: the smallest factor the loading rate was slowed to (1: never).
  double rateFactorMin = 1.0;
  // Every field, in the order a checkpoint holds them (stateio::Listed).
  template <class Self>
  static auto fields(Self& s) {
    return std::tie(s.records, s.strainRate, s.inertialNumber, s.maxLateralDeviation, s.maxSingleWallDeviation, s.steps,
                    s.rateFactorMin);
  }
};

class Laboratory {
 public:
  Laboratory(const RunConfig& config, ProgressFn progress = {});
  // A copy has its own boundary control over its own engine and its own protocol (they refer to the
  // laboratory's engine and config), in the state of the original's.
  Laboratory(const Laboratory& other);
  Laboratory& operator=(const Laboratory&) = delete;

  // Draws the grading, places particles loosely and prepares the sample (compaction with the
  // preparation friction, searched when not given, or frictionless growth), then re-equilibrates at
  // full stiffness with friction restored.
  PreparationResult prepare();
  // The checks prepare() or adoptPacking() make before their first step (the sample drawn and
  // placed, or the packing taken, and the solver configured: the time step against the critical
  // one, the size of a periodic cell), without preparing: `check` and `run` make them up front
  // (lab/preflight.hpp). Leaves simulation() and d50() as that first step would see them.
  void checkSample(const Simulation* packed);
  double d50() const { return d50_; }
  // Starts from a given packing (particles and boundary already in `packed`): equilibrium at full
  // stiffness and friction at the confining pressure, no compaction and no e0 search.
  PreparationResult adoptPacking(Simulation packed);
  // The small-strain probe of the consolidated sample (test.probe_strain, lab/moduli.hpp): E0 and
  // nu0; the engine is left exactly as it was.
  ModulusProbe probeModuli();
  static constexpr double kProbeUnbalanced = 1e-3;
  static constexpr double kProbeStressTolerance = 1e-3;  // reference state: stresses within 1e-3 p
  static constexpr double kProbeLateralFraction = 1e-2;  // probed state: lateral within 1 % of d_sigma1
  static constexpr long kProbeSteps = 1000;
  static constexpr long kProbeMaxSteps = 2'000'000;
  // Shearing of the prepared sample to the final strain: beginShear() then continueShear().
  ShearResult shear();
  void beginShear();
  // Runs (or, after loadState, resumes) the shearing to the final strain.
  ShearResult continueShear();
  bool shearStarted() const { return shear_.started; }

  // Checkpoints every `everyStrain` of strain during shearing.
  void onCheckpoint(CheckpointFn fn, double everyStrain) {
    checkpoint_ = std::move(fn);
    checkpointEvery_ = everyStrain;
  }
  // Exact binary state (engine, grain records and shearing protocol) for checkpoints.
  void saveState(std::ostream& out) const;
  void loadState(std::istream& in);

  // Snapshots every `everyStrain` of strain during shearing (and at its start and end).
  void onSnapshot(SnapshotFn fn, double everyStrain) {
    snapshot_ = std::move(fn);
    snapshotEvery_ = everyStrain;
  }

  Simulation& simulation() { return sim_; }
  const Simulation& simulation() const { return sim_; }
  const GrainRecords& grainRecords() const { return records_; }
  // Consolidates to an isotropic stress p until stress and unbalanced force meet the tolerances.
  long consolidate(double pressure, const std::string& phase);
  EquilibriumState equilibriumState() const;
  // Grain displacement, rotation, local strain and shear band since the start of shearing; the
  // neighbourhood of the local strain is kNeighbourhoodDiameters * d50.
  GrainKinematics currentKinematics() const;
  // The shear band of those kinematics (lab/shear_band.hpp, bins of d50); none in a periodic cell,
  // where a band may wrap across the faces.
  std::optional<ShearBand> shearBand(const GrainKinematics& k) const;
  // The same since the start of the previous band window: the strain increment of the window closed
  // last and of the part of the current one (the whole test before the first window closes).
  GrainKinematics incrementKinematics() const;
  // The band of the last closed window (nullopt: none found there, or no window closed yet:
  // bandWindows() = 0), from the window's strain increment.
  std::optional<ShearBand> lastShearBand() const {
    return shear_.bandFound ? std::optional<ShearBand>(shear_.band) : std::nullopt;
  }
  long bandWindows() const { return shear_.bandWindows; }
  static constexpr double kNeighbourhoodDiameters = 2.0;
  static constexpr double kPlatenRampIntegralTimes = 40.0;
  static constexpr double kAutoInertialNumber = 0.98e-3;
  // Platen speed during an unload–reload loop, as a fraction of the loading speed: slow enough that
  // an unload (~1e-4 of strain) lasts several wave transit times of the sample.
  static constexpr double kLoopSpeedFactor = 0.1;
  // Records during a loop every this fraction of output.record_every_strain of platen travel.
  static constexpr double kLoopRecordFraction = 1e-2;
  // test.loop_rest: the rest ends when the unbalanced-force ratio is below kProbeUnbalanced (checked
  // every kSlowdownCheckSteps steps) or after kLoopMaxRestSteps; a record every kLoopRestRecordSteps.
  static constexpr long kLoopMaxRestSteps = 200'000;
  static constexpr long kLoopRestRecordSteps = 200;
  // Platen slow-down: the unbalanced force is checked every kSlowdownCheckSteps steps; the speed
  // never falls below kMinPlatenSlowdown of the loading speed.
  static constexpr long kSlowdownCheckSteps = 10;
  static constexpr double kMinPlatenSlowdown = 0.05;
  // test.rate_follows_pressure: the rate follows sqrt(p'/(kPressureRateHeadroom p0)), checked every
  // kSlowdownCheckSteps steps, at most 1 and never below kMinPressureRateFactor of the rate at p0 (I
  // stays under its p0 value down to p' = kMinPressureRateFactor^2 p0 = 4e-4 p0). The headroom
  // covers the stress's fluctuation between a check and the records' mean (measured: up to 6 %
  // in a liquefying 300-grain cell), which would otherwise carry I a little above its p0 value.
  static constexpr double kMinPressureRateFactor = 0.02;
  static constexpr double kPressureRateHeadroom = 1.1;
  // A record of the current state; the boundary stresses are meanStress when given (the mean over
  // the recording interval, as a load cell reports it), else the instantaneous ones.
  Record measure(const Vec3* meanStress = nullptr, double meanShearStress = 0.0) const;
  // The micromechanical columns of the records (names, in order).
  std::vector<std::string> microColumnNames() const { return lab::microColumnNames(microColumns_); }
  const MicroAnalyzer& microAnalyzer() const { return micro_; }
  // The stages of the shearing pipeline, in order (for the summary and the docs).
  std::vector<std::string> shearStageNames();

 private:
  RunConfig config_;
  ProgressFn progress_;
  SnapshotFn snapshot_;
  double snapshotEvery_ = 0.0;
  CheckpointFn checkpoint_;
  double checkpointEvery_ = 0.0;
  // Where the shearing stands (all of it goes into a checkpoint).
  struct ShearState {
    bool started = false;
    double h0 = 0.0, v0 = 0.0;
    Vec3 l0 = Vec3::Zero();
    long rampSteps = 1, startStep = 0;
    double nextRecord = 0.0, nextSnapshot = 0.0, nextCheckpoint = 0.0;
    // Boundary stresses summed over the steps since the last record: a record carries their mean.
    Vec3 stressSum = Vec3::Zero();
    double shearStressSum = 0.0;
    std::array<double, 6> wallStressSum{};
    long stressSamples = 0;
    double elastic0 = 0.0, kinetic0 = 0.0;  // energies at the start of shearing [J]
    ShearResult result;
    // Unload–reload loops: the next loop of test.unload_reload_at, the current phase (as
    // Record::loopPhase), the deviator at the reversal, the step the last loop ended (-1: none).
    int loopNext = 0, loopPhase = 0;
    double loopQ = 0.0;
    long loopEndStep = -1;
    long loopRestStart = -1;   // the step a rest before an unload began (test.loop_rest)
    bool forceRecord = false;  // a record at a loop's reversal, turning point or end (same step)
    double slowdown = 1.0;     // platen speed factor from the unbalanced force (test.platen_slowdown_unbalanced)
    double pressureFactor = 1.0;  // loading-rate factor sqrt(p'/p0) (test.rate_follows_pressure)
    // The shear band's strain windows (output.band_strain_window): the driving strain at the start
    // of the current window, the box lengths there and at the previous one's (their grains in
    // window_, previousWindow_), the windows closed, and the band of the last one.
    double windowStrain = 0.0;
    Vec3 windowLengths = Vec3::Zero(), previousWindowLengths = Vec3::Zero();
    long bandWindows = 0;
    bool bandFound = false;
    ShearBand band;
    // Every field, in the order a checkpoint holds them (stateio::Listed): one list for saveState
    // and loadState, checked against the struct's field count at compile time.
    template <class Self>
    static auto fields(Self& s) {
      return std::tie(s.started, s.h0, s.v0, s.l0, s.rampSteps, s.startStep, s.nextRecord, s.nextSnapshot,
                      s.nextCheckpoint, s.stressSum, s.shearStressSum, s.wallStressSum, s.stressSamples, s.elastic0,
                      s.kinetic0, s.result, s.loopNext, s.loopPhase, s.loopQ, s.loopEndStep, s.loopRestStart,
                      s.forceRecord, s.slowdown, s.pressureFactor, s.windowStrain, s.windowLengths,
                      s.previousWindowLengths, s.bandWindows, s.bandFound, s.band);
    }
  };

 public:
  // Fields of the shearing state a checkpoint holds (for the checkpoint's layout tag).
  static std::size_t shearStateFieldCount();
  // The shearing protocol of the test (null before beginShear) and the boundary's controls.
  const ShearProtocol* protocol() const { return protocol_.get(); }
  BoundaryControl& boundary() const { return *boundary_; }

 private:
  std::unique_ptr<ShearProtocol> protocol_;
  std::unique_ptr<BoundaryControl> boundary_;  // over sim_, made once the boundary kind is known
  // Platen speed factor of the current step: the start-up ramp, or a loop's (negative while unloading).
  double loadingFactor() const;
  ShearState shear_;
  Simulation sim_;
  GrainRecords records_;
  GrainRecords window_, previousWindow_;  // the grains at the start of the current and the previous band window
  // Kinematics since `reference`, the box lengths then being `lengths` (walls).
  GrainKinematics kinematicsSince(const GrainRecords& reference, const Vec3& lengths) const;
  // At a record that closes a band window: the band from the window's increment into r, and the next window.
  void closeBandWindow(Record& r, double strain);
  MicroAnalyzer micro_;
  MicroColumnSet microColumns_;
  double d50_ = 0.0;
  void placeSample(PreparationResult& result);
  std::vector<GrowthStage> growthCurve_;  // of the last growShapes(); preparation only, not in checkpoints
  void setFriction(double deg) { sim_.model.tanFriction = std::tan(degToRad(deg)); }
  long rampStiffness();
  long growRadii();
  // sample.method = "deposition": walls fixed, the cloud falls and settles under gravity (until the
  // unbalanced-force ratio is below solver.unbalanced_tolerance); then the top platen is brought
  // down onto the bed. Fills deposition_.
  long deposit();
  static constexpr double kSettledKineticFraction = 1e-3;
  std::optional<DepositionReport> deposition_;  // of the last deposit(); preparation only
  // sample.method = "under-compaction": each layer placed as a cloud above the bed (the first by
  // placeSample), rained and tamped by the top platen at a constant speed (kTampSteps steps from the
  // cloud's top to the layer's target height), held there until at rest, the platen lifted for the
  // next. Fills underCompaction_.
  long underCompact();
  // test.boundary = "membrane": the flexible membrane replaces the rigid cylinder the sample was
  // prepared in, and the sample comes to equilibrium in it at the confining pressure.
  long installMembrane();
  long settle(const std::string& phase, double work0);  // walls as they are, until at rest under gravity
  static constexpr long kTampSteps = 100000;
  std::vector<std::vector<double>> layerDiameters_;  // the grains of each layer (placeSample)
  std::optional<UnderCompactionReport> underCompaction_;
  std::vector<double> voidRatioProfile(int slices) const;
  // Frictionless growth of the grains chosen to be ellipsoids from their equal-volume spheres to
  // sample.shape, in steps of eccentricity with the boundary holding p after each ([O] §5.2-5.3).
  long growShapes();
  double compactWithFriction(const Simulation& loose, double muDeg, Simulation& out, long& steps);
  void buildShearPipeline(Pipeline& pipeline);
};

// Gives every grain its rolling friction (contact.model = "rolling-linear"): the uniform
// contact.rolling_friction, or c psi^k with psi drawn from contact.sphericity (seeded); returns the
// grains' sphericities (1 where none was drawn).
std::vector<double> assignRollingFriction(const RunConfig& config, Particles& particles);

// Sets up the contact model, damping, servo and time step of a simulation from the config.
// Throws InputError when an explicit solver.dt exceeds the critical time step (unless forced).
void configureSolver(const RunConfig& config, Simulation& sim);

// Holds every normal stress of the boundary at p (walls or cell), no shear.
void holdIsotropicStress(Simulation& sim, double pressure);

}  // namespace grainlab::lab

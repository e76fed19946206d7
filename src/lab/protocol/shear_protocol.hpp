#pragma once
// A shearing test as a small object (one file each in lab/protocol/): it sets the boundary's
// controls at the start, drives them before every step, keeps its own state, says how far the test
// has gone and when it ends, and fills its own record columns. Laboratory::beginShear /
// continueShear run every protocol the same way (records, snapshots, checkpoints, unload–reload
// loops, progress) through BoundaryControl (lab/boundary_control.hpp).
#include <array>
#include <memory>
#include <optional>
#include <string>

#include "lab/boundary_control.hpp"
#include "lab/run_config.hpp"

namespace grainlab::lab {

struct Record;

// What any protocol keeps between steps, in one plain struct so that a checkpoint writes it as its
// bytes and the checkpoint's layout tag covers it (io/checkpoint_file.cpp).
struct ProtocolState {
  int direction = 1;            // oedometer, cyclic: +1 loading (compression), -1 unloading (extension)
  double path = 0.0;            // oedometer, cyclic: accumulated |d eps1| since the start [-]
  double lastEps1 = 0.0;        // axial strain at the previous step [-]
  long halfCycles = 0;          // cyclic: reversals so far (two per cycle)
  double cycleEpsMin = 0.0, cycleEpsMax = 0.0;  // cyclic: range of eps1 over the current cycle
  double doubleAmplitude = 0.0; // cyclic: largest double-amplitude axial strain of a cycle so far
  double ruMax = 0.0;           // undrained: largest ru = 1 - p'/p0 so far (every step)
  double liquefiedCycles = -1.0;  // cyclic: cycles to liquefaction (-1: not liquefied)
  double volumeDriftMax = 0.0;  // undrained: largest |eps_v| of any step
  bool done = false;            // the protocol's own end (oedometer unloaded, cyclic stopped)
  // Undrained with test.back_pressure: whether the pore water is cavitated now (its pressure held at
  // the cavitation pressure, the drained axes at the effective stress that gives), whether the
  // boundary's controls say so (they switch before the next step), how often it cavitated, and the
  // strain (the protocol's strain()) of the first cavitation (-1: never).
  bool cavitated = false;
  bool drainageOpen = false;
  long cavitations = 0;
  double cavitationStrain = -1.0;
  // Cavitated: the largest volume of the cavities (-eps_v) since the water cavitated.
  double cavityMax = 0.0;
  // Since the cavities last closed, u has risen above u_cav by kCavityMargin (true before any
  // cavitation): until then the water cavitates again only below u_cav by that margin.
  bool waterRecovered = true;
  // Records the protocol asks for besides those spaced in progress(): at a reversal, and once the
  // recorded quantity (oedometer: log10 sigma_v; cyclic: q) has moved by the protocol's step since
  // the last record.
  bool recordDue = false;
  double lastRecorded = 0.0;
  // Stress path: the point the current segment runs to (== the number of points: the path is
  // done), the value each axis's control starts the segment from, the targets of this step, the
  // largest |stress - target| / p0 of a stress-controlled axis, and whether an axis reached
  // test.final_axial_strain before the end (a stress target beyond the sample's strength).
  long segment = 0;
  std::array<double, 3> segmentStart{};
  std::array<double, 3> target{};
  double stressDeviationMax = 0.0;
  bool pathFailed = false;
  // Cyclic simple shear: gamma at the start (a prepared cell is slightly skewed; amplitudes are
  // measured from there), the amplitude being cycled (index into test.shear_strain_amplitudes),
  // gamma and tau of the previous step, and of the current cycle its ranges and the loop area
  // (the work per unit volume, the integral of tau dgamma); per amplitude the secant modulus, the
  // damping ratio and the half-range of gamma of the last cycle.
  static constexpr int kMaxAmplitudes = kMaxShearAmplitudes;
  double gamma0 = 0.0;
  long amplitude = 0;
  bool returning = false;  // after the last cycle of an amplitude: back to gamma0
  double lastGamma = 0.0, lastTau = 0.0;
  double cycleGammaMin = 0.0, cycleGammaMax = 0.0, cycleTauMin = 0.0, cycleTauMax = 0.0, loopArea = 0.0;
  std::array<double, kMaxAmplitudes> secantModulus{}, dampingRatio{}, measuredAmplitude{};
  long amplitudesDone = 0;
};

class ShearProtocol {
 public:
  explicit ShearProtocol(const RunConfig& config) : config_(config) {}
  virtual ~ShearProtocol() = default;
  // The protocol of config.test.type (not for "isotropic").
  static std::unique_ptr<ShearProtocol> make(const RunConfig& config);

  const TestTypeInfo& info() const { return lab::info(config_.test.type); }
  bool undrained() const { return info().drainage && config_.test.drainage == Drainage::Undrained; }
  // The strain rate the config gives (nullopt: "auto", from the inertial number).
  std::optional<double> givenRate() const;
  // The controls at the start of shearing (after BoundaryControl::beginTest).
  virtual void configure(BoundaryControl& b) = 0;
  // Before every step: the drive at `factor` of the loading rate `rate` (factor from the start-up
  // ramp, an unload–reload loop or the platen slow-down).
  virtual void drive(BoundaryControl& b, double rate, double factor) = 0;
  // After every step.
  virtual void afterStep(const BoundaryControl& b);
  // The strain the test imposes: axial engineering strain since the start, or gamma.
  virtual double strain(const BoundaryControl& b) const { return b.strain()[2]; }
  // A variable that only grows, which records, snapshots and checkpoints are spaced in: the strain
  // of monotonic tests, the accumulated |d eps1| of the reversing ones.
  virtual double progress(const BoundaryControl& b) const { return strain(b); }
  virtual bool finished(const BoundaryControl& b) const { return strain(b) >= config_.test.finalAxialStrain; }
  virtual double fractionDone(const BoundaryControl& b) const {
    return std::min(1.0, strain(b) / config_.test.finalAxialStrain);
  }
  // Lateral stress targets (x, y) the boundary is meant to hold, for how well it held them; none
  // where the lateral axes are strain-controlled.
  virtual std::optional<Vec3> lateralTargets(double sigma1) const;
  // Undrained: the excess pore pressure the volume constraint produces now, and the pore-pressure
  // ratio of the liquefaction criteria (triaxial: from the lateral stresses and p'; simple shear:
  // from sigma_zz).
  virtual double porePressure(const BoundaryControl& b) const { return excessPorePressure(b.stress()); }
  virtual double porePressureRatio(const BoundaryControl& b) const { return poreRatio(b.stress()); }
  // The protocol's own columns of a record (u, cycle).
  virtual void completeRecord(Record& r) const;
  // Whether the protocol wants a record after this step (ProtocolState::recordDue), and the record
  // that was taken.
  bool recordDue() const { return state.recordDue; }
  virtual void recorded(const Record&) { state.recordDue = false; }
  // "auto" rates of the reversing tests are this fraction of the inertial-number rate of the
  // monotonic tests: an oedometer or a stress cycle of a stiff sand spans strains of 1e-5 to 1e-3,
  // which the monotonic rate would cross in a few wave transit times of the sample.
  static constexpr double kReversingRateFactor = 0.01;
  virtual double autoRateFactor() const { return 1.0; }

  ProtocolState state;

 protected:
  const RunConfig& config_;
  // Excess pore pressure of an undrained test: the total lateral stress stays the cell pressure p0,
  // the effective one is what the grains carry.
  double excessPorePressure(const Vec3& sigma) const { return config_.test.confiningPressure - 0.5 * (sigma[0] + sigma[1]); }
  // After a step of an undrained test: the volume drift while the volume is held, ru, and
  // cavitation (test.back_pressure): the water cavitates once u falls to the cavitation pressure,
  // and the cavities close again when the sample has contracted back to its initial volume (once
  // they have opened by kCavityOpen: right after the switch the stress servo lags the platen, and
  // the volume first shrinks by a few 1e-6; closing there would chatter between the two controls).
  // Right after the cavities close, u is at u_cav to the stress servo's error: without a margin
  // the water would cavitate again on the next step and the sample compact while "cavitated"
  // (found in cyclic simple shear: eps_v reached +1e-3 with u held at u_cav). So after a closing
  // the water cavitates again only once u <= u_cav - kCavityMargin (p0 - u_cav), or at u_cav once
  // it has first risen above u_cav + that margin.
  void trackUndrained(const BoundaryControl& b);
  static constexpr double kCavityOpen = 1e-5;
  static constexpr double kCavityMargin = 5e-3;
  // Before a step of an undrained test (at the start of drive()): the boundary's controls follow
  // the cavitation state, through the two hooks below.
  void updateDrainage(BoundaryControl& b);
  // Cavitated: the axes that kept the volume hold the effective stress p0 - u_cav instead (the total
  // stress stays p0, the pore pressure u_cav). Closed: they keep the volume again.
  virtual void openDrainage(BoundaryControl& b, double effectiveStress) {
    b.holdStress(0, effectiveStress);
    b.holdStress(1, effectiveStress);
  }
  virtual void closeDrainage(BoundaryControl& b) {
    b.constantVolume(0);
    b.constantVolume(1);
  }
  // The excess pore-pressure ratio of the liquefaction criteria, ru = 1 - p'/p0: u less the q/3 of
  // the total stress path (with the cell pressure held, p_total = p0 + q/3), the same as u/p0
  // wherever q = 0.
  double poreRatio(const Vec3& sigma) const { return 1.0 - (sigma.sum() / 3.0) / config_.test.confiningPressure; }
};

}  // namespace grainlab::lab

// Cyclic triaxial: the deviator cycles between +q_cyc and -q_cyc, q_cyc = 2 csr p0, about the
// isotropic state at p0 (stress-controlled amplitude: the platens move at the axial strain rate and
// reverse when q reaches the amplitude, the way a servo-hydraulic press follows a stress signal at
// the rates of a DEM test). Drained, the lateral stresses are held at p0; undrained, the lateral
// axes keep the volume and u = p0 - sigma3'. The test stops at liquefaction (ru = 1 - p'/p0 >=
// test.ru_limit: the excess pore pressure less the q/3 of the total stress path, so that the
// criterion does not fire at the compression peak of each cycle;
// or a double-amplitude axial strain >= test.liquefaction_da_strain within a cycle) or after
// test.n_cycles cycles.
#include <cmath>

#include "lab/protocol/shear_protocol.hpp"
#include "lab/protocols.hpp"

namespace grainlab::lab {

namespace {
class CyclicTriaxial final : public ShearProtocol {
 public:
  using ShearProtocol::ShearProtocol;
  void configure(BoundaryControl& b) override {
    b.holdShape();
    if (undrained()) {
      b.constantVolume(0);
      b.constantVolume(1);
    } else {
      b.holdStress(0, config_.test.confiningPressure);
      b.holdStress(1, config_.test.confiningPressure);
    }
    b.imposeStrainRate(2, 0.0);
  }
  void drive(BoundaryControl& b, double rate, double factor) override {
    if (undrained()) updateDrainage(b);
    b.imposeStrainRate(2, rate, factor * state.direction);
  }
  void afterStep(const BoundaryControl& b) override {
    ShearProtocol::afterStep(b);
    const double eps1 = b.strain()[2];
    state.path += std::abs(eps1 - state.lastEps1);
    state.lastEps1 = eps1;
    state.cycleEpsMin = std::min(state.cycleEpsMin, eps1);
    state.cycleEpsMax = std::max(state.cycleEpsMax, eps1);
    state.doubleAmplitude = std::max(state.doubleAmplitude, state.cycleEpsMax - state.cycleEpsMin);
    const Vec3 s = b.stress();
    const double q = s[2] - 0.5 * (s[0] + s[1]);
    const double amplitude = 2.0 * config_.test.csr * config_.test.confiningPressure;
    if (std::abs(q - state.lastRecorded) >= kRecordFraction * amplitude) state.recordDue = true;
    if (state.direction > 0 && q >= amplitude) {
      state.direction = -1;
      ++state.halfCycles;
      state.recordDue = true;
    } else if (state.direction < 0 && q <= -amplitude) {
      state.direction = 1;
      ++state.halfCycles;
      state.recordDue = true;
      // A cycle is complete: the next one measures its own strain range.
      state.cycleEpsMin = state.cycleEpsMax = eps1;
    }
    const double ru = poreRatio(s);
    const bool liquefied = (undrained() && ru >= config_.test.ruLimit) ||
                           state.cycleEpsMax - state.cycleEpsMin >= config_.test.liquefactionDaStrain;
    if (liquefied && state.liquefiedCycles < 0.0) {
      // In the half cycle it happened in, counted in cycles (0.5: during the first compression).
      state.liquefiedCycles = 0.5 * static_cast<double>(state.halfCycles + 1);
      state.done = true;
      state.recordDue = true;
    }
    if (state.halfCycles >= 2 * config_.test.nCycles) state.done = true;
  }
  void recorded(const Record& r) override {
    state.recordDue = false;
    state.lastRecorded = r.q;
  }
  double autoRateFactor() const override { return kReversingRateFactor; }
  // A record every tenth of the amplitude of q, and at each reversal.
  static constexpr double kRecordFraction = 0.1;
  double progress(const BoundaryControl&) const override { return state.path; }
  bool finished(const BoundaryControl&) const override { return state.done; }
  double fractionDone(const BoundaryControl&) const override {
    return std::min(1.0, 0.5 * static_cast<double>(state.halfCycles) / static_cast<double>(config_.test.nCycles));
  }
  void completeRecord(Record& r) const override {
    ShearProtocol::completeRecord(r);
    r.cycle = 0.5 * static_cast<double>(state.halfCycles);
    r.loadDirection = state.direction;
  }
};
}  // namespace

std::unique_ptr<ShearProtocol> makeCyclicTriaxial(const RunConfig& c) { return std::make_unique<CyclicTriaxial>(c); }

}  // namespace grainlab::lab

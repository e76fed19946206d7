// Oedometric compression: no lateral strain, the axial strain rate imposed until the axial stress
// reaches test.max_axial_stress, then reversed until it has fallen to test.unload_axial_stress.
#include <cmath>

#include "lab/protocol/shear_protocol.hpp"
#include "lab/protocols.hpp"

namespace grainlab::lab {

namespace {
class Oedometer final : public ShearProtocol {
 public:
  using ShearProtocol::ShearProtocol;
  void configure(BoundaryControl& b) override {
    b.holdShape();
    b.fix(0);
    b.fix(1);
    b.imposeStrainRate(2, 0.0);
    state.lastEps1 = 0.0;
    state.lastRecorded = std::log10(std::max(b.stress()[2], 1e-300));
  }
  void drive(BoundaryControl& b, double rate, double factor) override {
    b.imposeStrainRate(2, rate, factor * state.direction);
  }
  void afterStep(const BoundaryControl& b) override {
    const double eps1 = b.strain()[2];
    state.path += std::abs(eps1 - state.lastEps1);
    state.lastEps1 = eps1;
    const double sigma1 = b.stress()[2];
    if (state.direction > 0 && sigma1 >= config_.test.maxAxialStress) {
      state.direction = -1;
      state.recordDue = true;
    } else if (state.direction < 0 && sigma1 <= config_.test.unloadAxialStress) {
      state.done = true;
    }
    if (sigma1 > 0.0 && std::abs(std::log10(sigma1) - state.lastRecorded) >= kRecordStepLog10) state.recordDue = true;
  }
  void recorded(const Record& r) override {
    state.recordDue = false;
    if (r.sigma1 > 0.0) state.lastRecorded = std::log10(r.sigma1);
  }
  double autoRateFactor() const override { return kReversingRateFactor; }
  // A record every 1/100 of a decade of sigma_v (about 100 per decade, for e - log sigma_v).
  static constexpr double kRecordStepLog10 = 0.01;
  double progress(const BoundaryControl&) const override { return state.path; }
  bool finished(const BoundaryControl&) const override { return state.done; }
  double fractionDone(const BoundaryControl& b) const override {
    // Half for the loading, half for the unloading, each in log sigma1.
    const double s = std::max(b.stress()[2], 1e-300), p0 = config_.test.confiningPressure;
    const double up = std::log(config_.test.maxAxialStress / p0);
    const double down = std::log(config_.test.maxAxialStress / config_.test.unloadAxialStress);
    const double f = state.direction > 0 ? 0.5 * std::log(s / p0) / up
                                         : 0.5 + 0.5 * std::log(config_.test.maxAxialStress / s) / down;
    return std::clamp(f, 0.0, 1.0);
  }
  void completeRecord(Record& r) const override { r.loadDirection = state.direction; }
};
}  // namespace

std::unique_ptr<ShearProtocol> makeOedometer(const RunConfig& c) { return std::make_unique<Oedometer>(c); }

}  // namespace grainlab::lab

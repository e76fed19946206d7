// Cyclic simple shear in the periodic cell (test.type = "cyclic-simple-shear"): strain-controlled
// cycles of gamma = H_xz/H_zz about its value at the start, gamma0, at each amplitude of
// test.shear_strain_amplitudes in turn (increasing): from gamma0 up to +gamma_a, then
// test.cycles_per_amplitude cycles +gamma_a -> -gamma_a -> +gamma_a, then back to gamma0 before
// the next amplitude. The x and y edges keep their length; drained, sigma_zz is held at p0;
// undrained, H_zz is fixed too (constant volume, u = p0 - sigma_zz).
//
// Per amplitude, over its last cycle (the one that closes the loop): the secant shear modulus
// G = (tau_max - tau_min)/(gamma_max - gamma_min), and the damping ratio of the hysteresis loop,
// xi = W_D / (4 pi W_S), W_D = the loop's area (the integral of tau dgamma over the cycle, by the
// trapezoidal rule every step) and W_S = G gamma_a^2 / 2 the strain energy of the secant at the
// half-range gamma_a (the definition of a resonant-column or cyclic simple shear campaign; e.g.
// Kramer, Geotechnical Earthquake Engineering, §6.4).
//
// The rate: test.shear_strain_rate, or "auto" (a tenth of the monotonic tests' inertial-number rate,
// kCyclicShearRateFactor), slowed where an amplitude is so small that a quarter cycle would last
// fewer than kMinQuarterSteps steps (a few wave transits of a sample), so the smallest amplitudes
// stay quasi-static too.
#include <cmath>

#include "lab/protocol/simple_shear_base.hpp"

namespace grainlab::lab {

namespace {
class CyclicSimpleShear final : public SimpleShearBase {
 public:
  using SimpleShearBase::SimpleShearBase;
  static constexpr double kMinQuarterSteps = 2000.0;
  static constexpr double kCyclicShearRateFactor = 0.1;
  static constexpr double kPi = 3.14159265358979323846;

  void configure(BoundaryControl& b) override {
    configureNormal(b);  // state.gamma0: the cell's skew at the start (Laboratory, shear.cpp)
    state.lastGamma = 0.0;
    state.lastTau = tauOf(b);
    state.direction = 1;
    state.amplitude = 0;
    state.halfCycles = 0;
    resetCycle(0.0, state.lastTau);
  }
  void drive(BoundaryControl& b, double rate, double factor) override {
    if (undrained()) updateDrainage(b);
    if (state.done) {
      b.imposeShearRate(0.0);
      return;
    }
    const double amplitude = config_.test.shearStrainAmplitudes[state.amplitude];
    const double dt = b.simulation().dt;
    const double slowest = amplitude / (kMinQuarterSteps * dt);
    b.imposeShearRate(std::min(rate, slowest), factor * state.direction);
  }
  void afterStep(const BoundaryControl& b) override {
    const double gamma = strain(b);
    const double tau = tauOf(b);
    state.path += std::abs(gamma - state.lastGamma);
    state.loopArea += 0.5 * (tau + state.lastTau) * (gamma - state.lastGamma);
    state.lastGamma = gamma;
    state.lastTau = tau;
    state.cycleGammaMin = std::min(state.cycleGammaMin, gamma);
    state.cycleGammaMax = std::max(state.cycleGammaMax, gamma);
    state.cycleTauMin = std::min(state.cycleTauMin, tau);
    state.cycleTauMax = std::max(state.cycleTauMax, tau);
    if (undrained()) trackUndrained(b);
    const std::vector<double>& amplitudes = config_.test.shearStrainAmplitudes;
    const double a = amplitudes[state.amplitude];
    if (std::abs(gamma - state.lastRecorded) >= kRecordFraction * a) state.recordDue = true;
    if (state.returning) {
      // Back at gamma0: the next amplitude, or the end.
      if (gamma <= 0.0) {
        state.returning = false;
        state.direction = 1;
        state.halfCycles = 0;
        state.recordDue = true;
        if (++state.amplitude >= static_cast<long>(amplitudes.size())) {
          state.amplitude = static_cast<long>(amplitudes.size()) - 1;
          state.done = true;
        }
      }
      return;
    }
    if (state.direction > 0 && gamma >= a) {
      state.recordDue = true;
      // Reversal at +gamma_a. halfCycles counts the reversals of this amplitude: the first is
      // the end of the initial quarter, every second one after it closes a cycle.
      if (state.halfCycles > 0 && state.halfCycles % 2 == 0) closeCycle();
      if (state.halfCycles >= 2 * config_.test.cyclesPerAmplitude) {
        state.returning = true;
        state.direction = -1;
        return;
      }
      ++state.halfCycles;
      state.direction = -1;
      resetCycle(gamma, tau);
      // The cycle measured starts here; the loop area counts from here.
      state.loopArea = 0.0;
    } else if (state.direction < 0 && gamma <= -a) {
      ++state.halfCycles;
      state.direction = 1;
      state.recordDue = true;
    }
  }
  void recorded(const Record& r) override {
    state.recordDue = false;
    state.lastRecorded = r.gamma;  // measured from gamma0
  }
  static constexpr double kRecordFraction = 0.1;
  double autoRateFactor() const override { return kCyclicShearRateFactor; }
  double progress(const BoundaryControl&) const override { return state.path; }
  bool finished(const BoundaryControl&) const override { return state.done; }
  double fractionDone(const BoundaryControl&) const override {
    const double n = static_cast<double>(config_.test.shearStrainAmplitudes.size());
    const double within = std::min(1.0, 0.5 * static_cast<double>(state.halfCycles) /
                                            static_cast<double>(config_.test.cyclesPerAmplitude + 1));
    return std::min(1.0, (static_cast<double>(state.amplitudesDone) + within) / n);
  }
  void completeRecord(Record& r) const override {
    SimpleShearBase::completeRecord(r);
    r.cycle = 0.5 * static_cast<double>(state.halfCycles);
    r.loadDirection = state.direction;
    r.pathSegment = state.amplitude + 1;
  }

 private:
  // The shear stress the sample opposes to the shear (Record::tau): -sigma_xz.
  static double tauOf(const BoundaryControl& b) {
    const Mat3& s = b.simulation().cell.stress;
    return -0.5 * (s(0, 2) + s(2, 0));
  }
  void resetCycle(double gamma, double tau) {
    state.cycleGammaMin = state.cycleGammaMax = gamma;
    state.cycleTauMin = state.cycleTauMax = tau;
  }
  // A cycle closed at +gamma_a: its secant modulus and damping ratio (the last cycle's stay).
  void closeCycle() {
    const long i = state.amplitude;
    const double halfRange = 0.5 * (state.cycleGammaMax - state.cycleGammaMin);
    const double g = (state.cycleTauMax - state.cycleTauMin) / (state.cycleGammaMax - state.cycleGammaMin);
    state.measuredAmplitude[i] = halfRange;
    state.secantModulus[i] = g;
    state.dampingRatio[i] = state.loopArea / (4.0 * kPi * 0.5 * g * halfRange * halfRange);
    state.amplitudesDone = std::max(state.amplitudesDone, i + 1);
  }
};
}  // namespace

std::unique_ptr<ShearProtocol> makeCyclicSimpleShear(const RunConfig& c) {
  return std::make_unique<CyclicSimpleShear>(c);
}

}  // namespace grainlab::lab

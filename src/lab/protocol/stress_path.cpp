// Stress path (test.type = "stress-path", lab/stress_path.hpp): the test advances a progress
// variable s at the test's rate (ds/dt = test.axial_strain_rate times the start-up ramp), and each
// axis follows its control of the current segment from where the segment began to the segment's
// end point, linearly in s. A stress-controlled axis gets the interpolated stress as its servo
// target; a strain-controlled axis moves each step by exactly what brings its engineering strain to
// the interpolated one (a dead-beat drive: the boundary's strain is kinematic, so it tracks the
// table without drift). A segment starts from its predecessor's end value where the control of the
// axis stays the same, and from the measured value where it changes (stress to strain or back), so
// no target jumps. The shear components of a periodic cell are held (principal axes fixed).
#include <cmath>

#include "lab/protocol/shear_protocol.hpp"
#include "lab/protocols.hpp"

namespace grainlab::lab {

namespace {
class StressPath final : public ShearProtocol {
 public:
  using ShearProtocol::ShearProtocol;
  void configure(BoundaryControl& b) override {
    b.holdShape();
    state.segment = 0;
    startSegment(b, nullptr);
    apply(b, 0.0);
  }
  void drive(BoundaryControl& b, double rate, double factor) override {
    const std::vector<PathPoint>& path = config_.test.path;
    if (state.segment >= static_cast<long>(path.size())) {
      // After the end: the last targets held, strain-controlled axes still.
      for (int a = 0; a < 3; ++a)
        if (path.back().control[a] == PathControl::Strain) b.fix(a);
      return;
    }
    const double dt = b.simulation().dt;
    state.path += rate * factor * dt;
    while (state.segment < static_cast<long>(path.size()) && state.path >= path[state.segment].s) {
      const PathPoint& reached = path[state.segment];
      ++state.segment;
      if (state.segment < static_cast<long>(path.size())) startSegment(b, &reached);
    }
    if (state.segment >= static_cast<long>(path.size())) {
      // The last point is reached: its targets are held for the step that ends the test.
      state.path = path.back().s;
      state.segment = static_cast<long>(path.size()) - 1;
      apply(b, dt);
      state.segment = static_cast<long>(path.size());
      return;
    }
    apply(b, dt);
  }
  void afterStep(const BoundaryControl& b) override {
    const std::vector<PathPoint>& path = config_.test.path;
    const PathPoint& to = path[std::min<long>(state.segment, static_cast<long>(path.size()) - 1)];
    const Vec3 sigma = b.stress();
    const Vec3 eps = b.strain();
    for (int a = 0; a < 3; ++a)
      if (to.control[a] == PathControl::Stress)
        state.stressDeviationMax =
            std::max(state.stressDeviationMax, std::abs(sigma[a] - state.target[a]) / config_.test.confiningPressure);
    if (state.segment >= static_cast<long>(path.size())) state.done = true;
    if (eps.cwiseAbs().maxCoeff() >= config_.test.finalAxialStrain) {
      state.pathFailed = true;
      state.done = true;
    }
  }
  double progress(const BoundaryControl&) const override { return state.path; }
  void completeRecord(Record& r) const override {
    r.pathS = state.path;
    r.pathSegment = std::min<long>(state.segment + 1, static_cast<long>(config_.test.path.size()));
  }
  bool finished(const BoundaryControl&) const override { return state.done; }
  double fractionDone(const BoundaryControl&) const override {
    return std::min(1.0, state.path / config_.test.path.back().s);
  }

 private:
  // The values each axis starts the current segment from: the end values of the point reached
  // where the control stays, the measured ones where it changes (or at the start of the path).
  void startSegment(const BoundaryControl& b, const PathPoint* reached) {
    const PathPoint& to = config_.test.path[state.segment];
    const Vec3 sigma = b.stress();
    const Vec3 eps = b.strain();
    for (int a = 0; a < 3; ++a) {
      if (reached && reached->control[a] == to.control[a]) state.segmentStart[a] = reached->value[a];
      else state.segmentStart[a] = to.control[a] == PathControl::Stress ? sigma[a] : eps[a];
    }
  }
  // Targets at the current s, and the drive that makes the boundary follow them within dt.
  void apply(BoundaryControl& b, double dt) {
    const std::vector<PathPoint>& path = config_.test.path;
    const PathPoint& to = path[state.segment];
    const double s0 = state.segment == 0 ? 0.0 : path[state.segment - 1].s;
    const double f = std::clamp((state.path - s0) / (to.s - s0), 0.0, 1.0);
    const Vec3 eps = b.strain();
    for (int a = 0; a < 3; ++a) {
      state.target[a] = state.segmentStart[a] + f * (to.value[a] - state.segmentStart[a]);
      if (to.control[a] == PathControl::Stress) b.holdStress(a, state.target[a]);
      else b.imposeStrainRate(a, dt > 0.0 ? (state.target[a] - eps[a]) / dt : 0.0);
    }
  }
};
}  // namespace

std::unique_ptr<ShearProtocol> makeStressPath(const RunConfig& c) { return std::make_unique<StressPath>(c); }

}  // namespace grainlab::lab

// Simple shear in the periodic cell (docs/laboratory.md §2): L_xz imposed, no lateral strain (the x and y
// edges keep their length); drained, the normal stress sigma_zz held; undrained, H_zz fixed too, so
// the volume is constant and u is the fall of sigma_zz from its initial value.
#include <cmath>

#include "lab/protocol/shear_protocol.hpp"
#include "lab/protocols.hpp"

namespace grainlab::lab {

namespace {
class SimpleShear final : public ShearProtocol {
 public:
  using ShearProtocol::ShearProtocol;
  void configure(BoundaryControl& b) override {
    b.holdShape();
    b.fix(0);
    b.fix(1);
    if (undrained()) b.fix(2);
    else b.holdStress(2, config_.test.confiningPressure);
  }
  void drive(BoundaryControl& b, double rate, double factor) override {
    if (undrained()) updateDrainage(b);
    b.imposeShearRate(rate, factor);
  }
  double strain(const BoundaryControl& b) const override {
    const Mat3& h = b.simulation().cell.h;
    return h(0, 2) / h(2, 2);
  }
  bool finished(const BoundaryControl& b) const override { return strain(b) >= config_.test.finalShearStrain; }
  double fractionDone(const BoundaryControl& b) const override {
    return std::min(1.0, strain(b) / config_.test.finalShearStrain);
  }
  void afterStep(const BoundaryControl& b) override {
    if (undrained()) trackUndrained(b);
  }
  // Undrained: u is the fall of sigma_zz from p0; cavitated, sigma_zz is held at p0 - u_cav.
  double porePressure(const BoundaryControl& b) const override { return config_.test.confiningPressure - b.stress()[2]; }
  double porePressureRatio(const BoundaryControl& b) const override {
    return 1.0 - b.stress()[2] / config_.test.confiningPressure;
  }
  void openDrainage(BoundaryControl& b, double effectiveStress) override { b.holdStress(2, effectiveStress); }
  void closeDrainage(BoundaryControl& b) override { b.fix(2); }
  void completeRecord(Record& r) const override {
    if (undrained()) r.u = config_.test.confiningPressure - r.sigma1;
  }
};
}  // namespace

std::unique_ptr<ShearProtocol> makeSimpleShear(const RunConfig& c) { return std::make_unique<SimpleShear>(c); }

}  // namespace grainlab::lab

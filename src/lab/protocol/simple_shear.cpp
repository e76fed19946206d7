// Simple shear in the periodic cell (docs/laboratory.md §2): L_xz imposed, no lateral strain (the x and y
// edges keep their length); drained, the normal stress sigma_zz held; undrained, H_zz fixed too, so
// the volume is constant and u is the fall of sigma_zz from its initial value.
#include <cmath>

#include "lab/protocol/simple_shear_base.hpp"

namespace grainlab::lab {

namespace {
class SimpleShear final : public SimpleShearBase {
 public:
  using SimpleShearBase::SimpleShearBase;
  void configure(BoundaryControl& b) override { configureNormal(b); }
  void drive(BoundaryControl& b, double rate, double factor) override {
    if (undrained()) updateDrainage(b);
    b.imposeShearRate(rate, factor);
  }
  bool finished(const BoundaryControl& b) const override { return strain(b) >= config_.test.finalShearStrain; }
  double fractionDone(const BoundaryControl& b) const override {
    return std::min(1.0, strain(b) / config_.test.finalShearStrain);
  }
  void afterStep(const BoundaryControl& b) override {
    if (undrained()) trackUndrained(b);
  }
};
}  // namespace

std::unique_ptr<ShearProtocol> makeSimpleShear(const RunConfig& c) { return std::make_unique<SimpleShear>(c); }

}  // namespace grainlab::lab

#pragma once
// What the two simple shear tests of the cell (simple_shear.cpp, cyclic_simple_shear.cpp) share:
// the x and y edges keep their length; drained, sigma_zz is held at p0; undrained, H_zz is fixed
// too (constant volume), u is the fall of sigma_zz from p0, and while the pore water is cavitated
// (test.back_pressure) sigma_zz is held at p0 - u_cav instead.
#include "lab/protocol/shear_protocol.hpp"
#include "lab/protocols.hpp"

namespace grainlab::lab {

class SimpleShearBase : public ShearProtocol {
 public:
  using ShearProtocol::ShearProtocol;
  double porePressure(const BoundaryControl& b) const override { return config_.test.confiningPressure - b.stress()[2]; }
  double porePressureRatio(const BoundaryControl& b) const override {
    return 1.0 - b.stress()[2] / config_.test.confiningPressure;
  }
  void completeRecord(Record& r) const override {
    if (undrained()) r.u = config_.test.confiningPressure - r.sigma1;
  }
  // gamma since the start of the test: the prepared cell's skew gamma0 is not shear the test imposed.
  double strain(const BoundaryControl& b) const override { return gammaOf(b) - state.gamma0; }

 protected:
  // The normal controls at the start of the test (the shear rate is the protocol's).
  void configureNormal(BoundaryControl& b) const {
    b.holdShape();
    b.fix(0);
    b.fix(1);
    if (undrained()) b.fix(2);
    else b.holdStress(2, config_.test.confiningPressure);
  }
  void openDrainage(BoundaryControl& b, double effectiveStress) override { b.holdStress(2, effectiveStress); }
  void closeDrainage(BoundaryControl& b) override { b.fix(2); }
  // gamma = H_xz / H_zz of the cell.
  static double gammaOf(const BoundaryControl& b) {
    const Mat3& h = b.simulation().cell.h;
    return h(0, 2) / h(2, 2);
  }
};

}  // namespace grainlab::lab

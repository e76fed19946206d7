#pragma once
// Axial compression at an imposed axial strain rate with the lateral axes stress-controlled along a
// stress path (triaxial, constant-p, true-triaxial), or at constant volume (undrained triaxial).
#include "lab/protocol/shear_protocol.hpp"

namespace grainlab::lab {

class AxialCompression : public ShearProtocol {
 public:
  using ShearProtocol::ShearProtocol;
  void configure(BoundaryControl& b) override;
  void drive(BoundaryControl& b, double rate, double factor) override;
  // Lateral targets (x, y) given the axial stress; none at constant volume. A granular sample
  // carries no tension, so a target is never below zero (at constant p that happens once
  // sigma1 > 3p, which a sample with strong contact moments can reach: the mean stress then exceeds
  // p, and the records show it).
  std::optional<Vec3> lateralTargets(double sigma1) const override;

 protected:
  // The path's targets before the tension cut (x, y).
  virtual Vec3 pathTargets(double /*sigma1*/) const { return Vec3(config_.test.confiningPressure, config_.test.confiningPressure, 0.0); }
  // Whether the targets follow sigma1 (set before every step).
  virtual bool followsAxialStress() const { return false; }
};

}  // namespace grainlab::lab

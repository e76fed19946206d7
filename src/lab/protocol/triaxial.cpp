// Triaxial compression (docs/laboratory.md §2): axial strain rate imposed; drained, the lateral stresses
// held at the confining pressure; undrained, the lateral axes keep the volume (the dry-sample
// analogue of an undrained test on saturated sand, u the change of lateral total stress the
// constraint produces).
#include "lab/protocol/axial_compression.hpp"

namespace grainlab::lab {

void AxialCompression::configure(BoundaryControl& b) {
  b.holdShape();
  if (undrained()) {
    b.constantVolume(0);
    b.constantVolume(1);
  } else {
    const Vec3 t = pathTargets(config_.test.confiningPressure);
    b.holdStress(0, t[0]);
    b.holdStress(1, t[1]);
  }
  b.imposeStrainRate(2, 0.0);
}

void AxialCompression::drive(BoundaryControl& b, double rate, double factor) {
  if (undrained()) updateDrainage(b);
  b.imposeStrainRate(2, rate, factor);
  if (followsAxialStress()) {
    // The stress path: lateral targets follow the axial stress of the previous step.
    const Vec3 target = *lateralTargets(b.stress()[2]);
    b.holdStress(0, target[0]);
    b.holdStress(1, target[1]);
  }
}

std::optional<Vec3> AxialCompression::lateralTargets(double sigma1) const {
  if (undrained()) return std::nullopt;
  return pathTargets(sigma1).cwiseMax(0.0);
}

std::unique_ptr<ShearProtocol> makeTriaxial(const RunConfig& c) { return std::make_unique<AxialCompression>(c); }

}  // namespace grainlab::lab

// True triaxial at constant p and b = (sigma2 - sigma3)/(sigma1 - sigma3).
#include "lab/protocol/axial_compression.hpp"

namespace grainlab::lab {

namespace {
class TrueTriaxial final : public AxialCompression {
 public:
  using AxialCompression::AxialCompression;

 protected:
  Vec3 pathTargets(double sigma1) const override {
    // p = (s1 + s2 + s3)/3 and b held: s3 = (3p - (1 + b) s1)/(2 - b).
    const double p = config_.test.confiningPressure, b = config_.test.b;
    const double s3 = (3.0 * p - (1.0 + b) * sigma1) / (2.0 - b);
    return Vec3(s3 + b * (sigma1 - s3), s3, 0.0);
  }
  bool followsAxialStress() const override { return true; }
};
}  // namespace

std::unique_ptr<ShearProtocol> makeTrueTriaxial(const RunConfig& c) { return std::make_unique<TrueTriaxial>(c); }

}  // namespace grainlab::lab

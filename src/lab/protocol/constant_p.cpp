// Compression at constant mean stress ([O]): the lateral stresses follow (3p - sigma1)/2.
#include "lab/protocol/axial_compression.hpp"

namespace grainlab::lab {

namespace {
class ConstantP final : public AxialCompression {
 public:
  using AxialCompression::AxialCompression;

 protected:
  Vec3 pathTargets(double sigma1) const override {
    const double lateral = 0.5 * (3.0 * config_.test.confiningPressure - sigma1);
    return Vec3(lateral, lateral, 0.0);
  }
  bool followsAxialStress() const override { return true; }
};
}  // namespace

std::unique_ptr<ShearProtocol> makeConstantP(const RunConfig& c) { return std::make_unique<ConstantP>(c); }

}  // namespace grainlab::lab

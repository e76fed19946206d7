#include "lab/protocol/shear_protocol.hpp"

#include <cmath>

#include "lab/protocols.hpp"

namespace grainlab::lab {

std::unique_ptr<ShearProtocol> makeTriaxial(const RunConfig& c);
std::unique_ptr<ShearProtocol> makeConstantP(const RunConfig& c);
std::unique_ptr<ShearProtocol> makeTrueTriaxial(const RunConfig& c);
std::unique_ptr<ShearProtocol> makeSimpleShear(const RunConfig& c);
std::unique_ptr<ShearProtocol> makeOedometer(const RunConfig& c);
std::unique_ptr<ShearProtocol> makeCyclicTriaxial(const RunConfig& c);
std::unique_ptr<ShearProtocol> makeStressPath(const RunConfig& c);
std::unique_ptr<ShearProtocol> makeCyclicSimpleShear(const RunConfig& c);

std::unique_ptr<ShearProtocol> ShearProtocol::make(const RunConfig& c) {
  switch (c.test.type) {
    case TestType::Triaxial: return makeTriaxial(c);
    case TestType::ConstantP: return makeConstantP(c);
    case TestType::TrueTriaxial: return makeTrueTriaxial(c);
    case TestType::SimpleShear: return makeSimpleShear(c);
    case TestType::Oedometer: return makeOedometer(c);
    case TestType::CyclicTriaxial: return makeCyclicTriaxial(c);
    case TestType::StressPath: return makeStressPath(c);
    case TestType::CyclicSimpleShear: return makeCyclicSimpleShear(c);
    case TestType::Isotropic: break;
  }
  throw std::logic_error("an isotropic test has no shearing protocol");
}

std::optional<double> ShearProtocol::givenRate() const {
  return info().strain == DrivingStrain::Shear ? config_.test.shearStrainRate : config_.test.axialStrainRate;
}

void ShearProtocol::afterStep(const BoundaryControl& b) {
  if (undrained()) trackUndrained(b);
}

void ShearProtocol::trackUndrained(const BoundaryControl& b) {
  const double epsV = b.volumetricStrain();
  // The drift is what the constraint lets through: not the cavities' volume while cavitated.
  if (!state.cavitated) state.volumeDriftMax = std::max(state.volumeDriftMax, std::abs(epsV));
  state.ruMax = std::max(state.ruMax, porePressureRatio(b));
  const std::optional<double> uCav = config_.test.cavitationPressure();
  if (!uCav) return;
  const double u = porePressure(b);
  const double margin = kCavityMargin * (config_.test.confiningPressure - *uCav);
  if (!state.cavitated && !state.waterRecovered && u > *uCav + margin) state.waterRecovered = true;
  if (!state.cavitated && u <= *uCav - (state.waterRecovered ? 0.0 : margin)) {
    state.cavitated = true;
    ++state.cavitations;
    if (state.cavitationStrain < 0.0) state.cavitationStrain = std::max(0.0, strain(b));
    state.cavityMax = 0.0;
    state.recordDue = true;
  } else if (state.cavitated) {
    state.cavityMax = std::max(state.cavityMax, -epsV);
  }
  if (state.cavitated && state.cavityMax >= kCavityOpen && epsV >= 0.0) {
    // Back at (or below) the initial volume: the vapour has condensed, the water is continuous
    // again and takes tension or pressure as before.
    state.cavitated = false;
    state.waterRecovered = false;
    state.recordDue = true;
  }
}

void ShearProtocol::updateDrainage(BoundaryControl& b) {
  if (state.cavitated == state.drainageOpen) return;
  if (state.cavitated) openDrainage(b, config_.test.confiningPressure - *config_.test.cavitationPressure());
  else closeDrainage(b);
  state.drainageOpen = state.cavitated;
}

std::optional<Vec3> ShearProtocol::lateralTargets(double) const { return std::nullopt; }

void ShearProtocol::completeRecord(Record& r) const {
  if (undrained()) r.u = excessPorePressure(Vec3(r.sigma2, r.sigma3, r.sigma1));
}

}  // namespace grainlab::lab

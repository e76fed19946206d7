// The two moment limits of the Kozicki–Donzé law: [W]'s eta (RA+RB)/2 |Fn| on the whole moment, and
// YADE's eta min(RA,RB) |Fn| on bending and twisting separately (the comparison variant).
#include <gtest/gtest.h>

#include "contact/models.hpp"

using namespace grainlab;

namespace {

// Loads a contact with normal x by a large relative rotation about `axis` in one step and returns
// the moment it ends with.
Vec3 momentAfterRotation(const contact::SphereContactModel& model, const Vec3& axis) {
  const double rA = 1e-3, rB = 2e-3, overlap = 1e-6;
  contact::ContactHistory h;
  h.touching = true;
  h.prevNormal = Vec3::UnitX();
  contact::ContactKinematics k;
  k.normal = Vec3::UnitX();
  k.prevNormal = Vec3::UnitX();
  k.overlap = overlap;
  k.relativeVelocity = Vec3::Zero();
  k.relativeSpin = axis * 10.0;  // rad/s
  k.meanSpinNormal = 0.0;
  k.dt = 1e-2;                   // 0.1 rad: far beyond the elastic range
  contact::applyLaw(model.pairParams(rA, rB), k, h);
  return h.moment;
}

}  // namespace

TEST(MomentLimit, WCombinedAgainstYadeSeparate) {
  contact::SphereContactModel model;
  const double rA = 1e-3, rB = 2e-3, overlap = 1e-6;
  const double fn = 2.0 * model.young * rA * rB / (rA + rB) * overlap;
  const Vec3 both = Vec3(1.0, 1.0, 0.0).normalized();  // twisting (x) and bending (y) together
  // [W]: the whole moment is capped at eta (RA+RB)/2 |Fn|, along the rotation.
  const Vec3 w = momentAfterRotation(model, both);
  EXPECT_NEAR(w.norm(), model.eta * 0.5 * (rA + rB) * fn, 1e-12 * w.norm());
  EXPECT_NEAR(w.normalized().dot(both), 1.0, 1e-12);
  // YADE: bending and twisting each capped at eta min(RA,RB) |Fn|, so |M| = sqrt(2) of that.
  model.yadeMomentLimit = true;
  const Vec3 y = momentAfterRotation(model, both);
  const double cap = model.eta * std::min(rA, rB) * fn;
  EXPECT_NEAR(y.x(), cap, 1e-12 * cap);
  EXPECT_NEAR(y.y(), cap, 1e-12 * cap);
  EXPECT_NEAR(y.norm(), std::sqrt(2.0) * cap, 1e-12 * cap);
  // Pure bending: one cap either way, but the arms differ (min radius against mean radius).
  EXPECT_NEAR(momentAfterRotation(model, Vec3::UnitY()).norm(), cap, 1e-12 * cap);
}

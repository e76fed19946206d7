// The contact-law slots and the Kozicki–Donzé preset against hand-computed values.
#include <gtest/gtest.h>

#include <cmath>

#include "contact/models.hpp"
#include "contact/slots.hpp"

using namespace grainlab;
using namespace grainlab::contact;

TEST(NormalSlot, LinearAndNoTension) {
  EXPECT_DOUBLE_EQ(normalLinear(2.0, 0.5, Vec3::UnitX()).x(), 1.0);
  EXPECT_DOUBLE_EQ(normalLinear(2.0, -0.5, Vec3::UnitX()).norm(), 0.0);
}

TEST(KozickiDonze, PairParametersFollowW) {
  SphereContactModel m;  // Ec 30 GPa, nu 0.3, beta 0.15, eta 1
  const double rA = 1e-3, rB = 3e-3;
  const PairParams p = m.pairParams(rA, rB);
  const double kn = 2.0 * 30e9 * rA * rB / (rA + rB);
  EXPECT_DOUBLE_EQ(p.kn, kn);
  EXPECT_DOUBLE_EQ(p.ks, 0.3 * kn);
  EXPECT_DOUBLE_EQ(p.kr, 0.15 * 0.3 * kn * rA * rB);
  EXPECT_DOUBLE_EQ(p.momentLimitArm, 1.0 * 0.5 * (rA + rB));
  // [W]'s Kn = Ec d50 / 2 for equal spheres of diameter d50 (7.5 MN/m for d50 = 0.5 mm).
  EXPECT_NEAR(m.pairParams(0.25e-3, 0.25e-3).kn, 7.5e6, 1e-6);
  // Against a wall: Kn = 2 Ec R, Kr = beta Ks R^2 when the wall is frictional, none when smooth.
  EXPECT_DOUBLE_EQ(m.wallParams(rA, 0.5).kn, 2.0 * 30e9 * rA);
  EXPECT_DOUBLE_EQ(m.wallParams(rA, 0.5).kr, 0.15 * 0.3 * 2.0 * 30e9 * rA * rA * rA);
  EXPECT_DOUBLE_EQ(m.wallParams(rA, 0.0).kr, 0.0);
}

TEST(ContactFrameRotation, IsARotationIntoTheNewTangentPlane) {
  const Vec3 n0 = Vec3::UnitZ();
  const Vec3 n1 = Vec3(0.3, -0.2, 1.0).normalized();
  const Vec3 fs(2.0, 1.0, 0.0);  // in the plane of n0
  const Vec3 carried = contactFrameRotation(n0, n1, 0.37) * fs;
  EXPECT_NEAR(carried.norm(), fs.norm(), 1e-12);
  EXPECT_NEAR(carried.dot(n1), 0.0, 1e-12);  // lies in the new tangent plane
  // The tilt part is the exact rotation taking n0 onto n1.
  EXPECT_NEAR((contactFrameRotation(n0, n1, 0.0) * n0 - n1).norm(), 0.0, 1e-14);
  // A twist of one step's size (1e-4 rad) about z turns x by that angle to O(theta^3).
  const double theta = 1e-4;
  const Vec3 t = contactFrameRotation(n0, n0, theta) * Vec3::UnitX();
  EXPECT_NEAR((t - Vec3(std::cos(theta), std::sin(theta), 0.0)).norm(), 0.0, 1e-13);
}

TEST(TangentialSlot, ElasticThenCoulombSliding) {
  const double ks = 1e6, fn = 10.0, tanMu = std::tan(degToRad(30.0));
  const Vec3 n = Vec3::UnitZ();
  Vec3 fs = Vec3::Zero();
  const double step = 1e-7;  // tangential displacement of B per step, along +x
  bool slid = false;
  for (int i = 1; i <= 200; ++i) {
    const SlipResult r = tangentialCoulomb(fs, ks, Vec3(step, 0, 0), n, fn, tanMu);
    fs = r.shearForce;
    const double elastic = ks * step * i;
    if (elastic <= fn * tanMu) {
      // Elastic: Fs = -Ks * total displacement (it opposes B's sliding).
      EXPECT_NEAR(fs.x(), -elastic, 1e-9 * elastic);
      EXPECT_FALSE(r.sliding);
    } else {
      EXPECT_NEAR(fs.norm(), fn * tanMu, 1e-12);  // exactly at the Coulomb limit
      EXPECT_LT(fs.x(), 0.0);
      slid = slid || r.sliding;
    }
  }
  EXPECT_TRUE(slid);
}

TEST(MomentSlot, ElasticThenPlateau) {
  const double kr = 2.0, limit = 0.01;
  Vec3 m = Vec3::Zero();
  const Vec3 dTheta(0, 1e-4, 0);
  for (int i = 1; i <= 100; ++i) {
    m = momentElasticPlastic(m, kr, dTheta, limit).moment;
    EXPECT_NEAR(m.y(), std::min(kr * 1e-4 * i, limit), 1e-15);
  }
}

// The whole law on one contact: normal approach fixed, relative rotation of B about a tangent
// axis (bending) and about the normal (twisting). Kozicki–Donzé resists both with the same Kr and
// saturates at eta (RA+RB)/2 |Fn|; beta = 0 gives no moment at all.
class LawMoment : public ::testing::TestWithParam<Vec3> {};

TEST_P(LawMoment, GrowsAsKrThetaAndPlateaus) {
  SphereContactModel model;
  const double rA = 2e-3, rB = 3e-3, overlap = 1e-6, dt = 1e-6;
  const PairParams p = model.pairParams(rA, rB);
  const double fn = p.kn * overlap;
  const double limit = model.eta * 0.5 * (rA + rB) * fn;
  const Vec3 spinAxis = GetParam();
  const double spin = 5.0;  // [rad/s] of B relative to A
  ContactHistory h;
  h.prevNormal = Vec3::UnitZ();
  h.touching = true;
  for (int i = 1; i <= 4000; ++i) {
    ContactKinematics k{Vec3::UnitZ(), h.prevNormal, overlap, Vec3::Zero(), spin * spinAxis,
                        0.5 * spin * spinAxis.dot(Vec3::UnitZ()), dt};
    const ContactResponse r = applyLaw(p, k, h);
    const double expected = std::min(p.kr * spin * dt * i, limit);
    EXPECT_NEAR(r.moment.norm(), expected, 1e-9 * limit) << "step " << i;
    EXPECT_NEAR(r.moment.normalized().dot(spinAxis), 1.0, 1e-9);
  }
  EXPECT_NEAR(h.moment.norm(), limit, 1e-12 * limit);  // reached the plateau

  SphereContactModel noRolling = model;
  noRolling.beta = 0.0;
  ContactHistory h0;
  h0.prevNormal = Vec3::UnitZ();
  ContactKinematics k{Vec3::UnitZ(), Vec3::UnitZ(), overlap, Vec3::Zero(), spin * spinAxis, 0.0, dt};
  EXPECT_EQ(applyLaw(noRolling.pairParams(rA, rB), k, h0).moment.norm(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(BendingAndTwisting, LawMoment,
                         ::testing::Values(Vec3::UnitX(), Vec3::UnitZ()));

// The smooth-contact shortcut (tan mu = 0, kr = 0: smooth walls, growth at mu = 0) gives the force of
// the full law, whatever shear and moment the history carried in and however the bodies move; the
// full law scales its trial shear to the zero Coulomb limit and leaves the moment slot off.
TEST(NormalOnlyLaw, EqualsTheFullLawWithoutFrictionOrMoment) {
  const contact::SphereContactModel model;
  contact::PairParams p = model.wallParams(2e-3, 0.0);
  ASSERT_EQ(p.tanFriction, 0.0);
  ASSERT_EQ(p.kr, 0.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double a = 0.37 * trial, b = 0.11 * trial * trial;
    contact::ContactKinematics k;
    k.normal = Vec3(std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), std::cos(a));
    k.prevNormal = (k.normal + Vec3(1e-3 * std::cos(b), 2e-3, -1e-3 * std::sin(a))).normalized();
    k.overlap = 1e-6 * (1 + trial % 7);
    k.relativeVelocity = Vec3(0.01 * std::cos(3 * a), -0.02, 0.005 * trial);
    k.relativeSpin = Vec3(1.0, -2.0 * std::sin(b), 0.5);
    k.meanSpinNormal = 0.3;
    k.dt = 1e-6;
    contact::ContactHistory full, shortcut;
    full.shearForce = shortcut.shearForce = Vec3(0.1 * trial, -0.05, 0.02);  // left over from friction
    full.moment = shortcut.moment = Vec3(1e-4, 0.0, -2e-4);
    full.prevNormal = shortcut.prevNormal = k.prevNormal;
    full.touching = shortcut.touching = true;
    const contact::ContactResponse r1 = contact::applyLaw(p, k, full);
    const contact::ContactResponse r2 = contact::applyNormalLaw(p, k.normal, k.overlap, shortcut);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(r1.force[i] + 0.0, r2.force[i] + 0.0) << "trial " << trial;  // (+0.0: the sign of a zero)
      EXPECT_EQ(r1.moment[i] + 0.0, r2.moment[i] + 0.0);
      EXPECT_EQ(full.shearForce[i] + 0.0, shortcut.shearForce[i] + 0.0);
      EXPECT_EQ(full.moment[i] + 0.0, shortcut.moment[i] + 0.0);
    }
    EXPECT_EQ(r1.slipDissipation, r2.slipDissipation);
    EXPECT_EQ(r1.rollDissipation, r2.rollDissipation);
    EXPECT_EQ(full.prevNormal, shortcut.prevNormal);
  }
}

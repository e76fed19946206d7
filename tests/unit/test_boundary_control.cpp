// The boundary-control seam (lab/boundary_control.hpp) on both boundaries against hand numbers: an
// imposed engineering strain rate, a fixed axis, constant volume; and the undrained and oedometric
// response of a frictionless face-centred cubic lattice against its elastic constants, which follow
// from the lattice alone: with nearest-neighbour normal springs kn, C11 = 2 kn/a and C12 = kn/a
// (a the cubic lattice constant), so that
//   - uniaxial strain (oedometer) along a cubic axis gives K0 = C12/C11 = 1/2, which is
//     nu/(1 - nu) of the lattice (nu = C12/(C11 + C12) = 1/3 along a cubic axis), and
//     d sigma_z / d eps = C11;
//   - axial strain at constant volume gives d p' = 0 and an excess pore pressure u = -d sigma_x =
//     d q / 3 = d p of the total stress path: the analytic result for an isotropic elastic skeleton
//     under undrained loading, which a cubic lattice loaded along its axis shares.
#include <gtest/gtest.h>

#include <cmath>

#include "lab/boundary_control.hpp"
#include "lab/measurements.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

namespace {

// An empty wall box of the given lengths (no particles: the walls only follow their controls).
Simulation emptyBox(const Vec3& lengths) {
  Simulation sim = scenes::emptyScene(1.0, 0.0);
  sim.box.setBounds(Vec3::Zero(), lengths);
  sim.initialise();
  sim.dt = 1e-4;
  return sim;
}

}  // namespace

// Walls: a strain rate of the reference length moves each platen at rate L0/2; after n steps the
// engineering strain is rate n dt; a fixed axis keeps its length.
TEST(BoundaryControl, WallsImposeTheEngineeringStrainRate) {
  Simulation sim = emptyBox(Vec3(0.1, 0.12, 0.2));
  auto b = lab::BoundaryControl::of(sim);
  b->beginTest();
  b->imposeStrainRate(2, 0.5);
  b->fix(0);
  b->imposeStrainRate(1, -0.25, 2.0);  // extension at a factor: -0.5 1/s
  for (int i = 0; i < 1000; ++i) sim.step();
  const Vec3 e = b->strain();
  EXPECT_NEAR(e[2], 0.5 * 1000 * 1e-4, 1e-12);
  EXPECT_NEAR(e[1], -0.5 * 1000 * 1e-4, 1e-12);
  EXPECT_EQ(e[0], 0.0);
  EXPECT_NEAR(sim.box.lower(2).position, 0.5 * 0.5 * 0.2 * 0.1, 1e-12);  // lower platen moved L0 rate t / 2
}

// Walls at constant volume: the two lateral axes take up the axial strain, the volume stays at its
// reference to rounding (1e-12) through 40 % axial strain, and both lateral lengths follow
// L = sqrt(V0 / L_z) (by symmetry, equally).
TEST(BoundaryControl, WallsHoldConstantVolume) {
  Simulation sim = emptyBox(Vec3(0.1, 0.1, 0.2));
  auto b = lab::BoundaryControl::of(sim);
  b->beginTest();
  const double v0 = sim.volume();
  b->constantVolume(0);
  b->constantVolume(1);
  b->imposeStrainRate(2, 1.0);
  for (int i = 0; i < 4000; ++i) {
    sim.step();
    ASSERT_NEAR(sim.volume() / v0, 1.0, 1e-12) << "step " << i;
  }
  EXPECT_NEAR(b->strain()[2], 0.4, 1e-9);
  const double lateral = std::sqrt(v0 / sim.box.length(2));
  EXPECT_NEAR(sim.box.length(0), lateral, 1e-12);
  EXPECT_NEAR(sim.box.length(1), lateral, 1e-12);
  EXPECT_NEAR(b->volumetricStrain(), 0.0, 1e-12);
}

// One constant-volume axis takes the whole change (the other lateral axis fixed): plane strain at
// constant volume, L_x = V0 / (L_y L_z).
TEST(BoundaryControl, WallsConstantVolumeThroughOneAxis) {
  Simulation sim = emptyBox(Vec3(0.1, 0.1, 0.2));
  auto b = lab::BoundaryControl::of(sim);
  b->beginTest();
  const double v0 = sim.volume();
  b->constantVolume(0);
  b->fix(1);
  b->imposeStrainRate(2, 1.0);
  for (int i = 0; i < 2000; ++i) sim.step();
  EXPECT_NEAR(sim.box.length(1), 0.1, 1e-15);
  EXPECT_NEAR(sim.box.length(0), v0 / (0.1 * sim.box.length(2)), 1e-12);
}

namespace {

// A frictionless face-centred cubic lattice of n^3 cubic cells (4 n^3 spheres) in the periodic
// cell, the spheres overlapping by a fraction `overlap` of the diameter (an isotropic pre-stress),
// with the constant normal stiffness kn and no moments.
struct FccLattice {
  Simulation sim;
  double a = 0.0, kn = 0.0;
};
FccLattice fccLattice(int n, double overlap) {
  FccLattice l;
  const double d = 2e-3;
  l.a = d * std::sqrt(2.0) * (1.0 - overlap);  // nearest-neighbour distance a/sqrt 2 = d (1 - overlap)
  Simulation& sim = l.sim;
  sim = scenes::emptyScene(1.0, 0.0);
  sim.model.beta = 0.0;  // no rolling stiffness: normal springs only
  l.kn = 1e6;
  sim.model.constantKn = l.kn;
  sim.localDamping = 0.3;
  sim.boundary = Boundary::Periodic;
  sim.cell.setBox(Vec3::Constant(n * l.a));
  const Vec3 basis[4] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const Vec3& s : basis) sim.particles.addSphere((Vec3(i, j, k) + s + Vec3::Constant(0.25)) * l.a, 0.5 * d, 2600.0);
  sim.initialise();
  sim.dt = 0.3 * sim.criticalTimeStep();
  return l;
}

// Drives the axial strain by `strain` over `steps` steps, then holds it while the lattice rests.
void strainAxially(Simulation& sim, lab::BoundaryControl& b, double strain, int steps) {
  b.imposeStrainRate(2, strain / (steps * sim.dt));
  for (int i = 0; i < steps; ++i) sim.step();
  b.fix(2);
  for (int i = 0; i < steps; ++i) sim.step();
}

}  // namespace

TEST(FccLattice, PrestressIsIsotropic) {
  FccLattice l = fccLattice(3, 1e-3);
  l.sim.step();
  const Mat3 s = l.sim.cell.stress;
  EXPECT_GT(s(0, 0), 0.0);
  EXPECT_NEAR(s(0, 0), s(2, 2), 1e-9 * s(0, 0));
  EXPECT_NEAR(s(0, 1), 0.0, 1e-9 * s(0, 0));
}

// Oedometer: no lateral strain. K0 = d sigma_x / d sigma_z = C12/C11 = 1/2 = nu/(1 - nu), and the
// constrained modulus is C11 = 2 kn / a (the pre-stress changes both by about the overlap, 1e-3).
TEST(FccLattice, OedometerK0IsNuOverOneMinusNu) {
  FccLattice l = fccLattice(3, 1e-3);
  auto b = lab::BoundaryControl::of(l.sim);
  l.sim.step();
  b->beginTest();
  b->fix(0);
  b->fix(1);
  const Vec3 s0 = b->stress();
  const double strain = 2e-4;  // a fifth of the overlap: no contact opens
  strainAxially(l.sim, *b, strain, 2000);
  const Vec3 ds = b->stress() - s0;
  EXPECT_NEAR(ds[0] / ds[2], 0.5, 0.005);
  EXPECT_NEAR(ds[1] / ds[2], 0.5, 0.005);
  EXPECT_NEAR(ds[2] / b->strain()[2], 2.0 * l.kn / l.a, 0.01 * 2.0 * l.kn / l.a);
}

// Undrained (constant volume): the mean effective stress does not change, and the excess pore
// pressure u = -d sigma_lateral is d q / 3 = d p of the total stress path; the volume holds to
// rounding.
TEST(FccLattice, UndrainedPorePressureIsTheTotalMeanStressIncrement) {
  FccLattice l = fccLattice(3, 1e-3);
  auto b = lab::BoundaryControl::of(l.sim);
  l.sim.step();
  b->beginTest();
  b->constantVolume(0);
  b->constantVolume(1);
  const Vec3 s0 = b->stress();
  strainAxially(l.sim, *b, 2e-4, 2000);
  const Vec3 s = b->stress();
  const double dq = (s[2] - 0.5 * (s[0] + s[1])) - (s0[2] - 0.5 * (s0[0] + s0[1]));
  const double dp = (s.sum() - s0.sum()) / 3.0;
  const double u = 0.5 * (s0[0] + s0[1]) - 0.5 * (s[0] + s[1]);
  ASSERT_GT(dq, 0.0);
  EXPECT_LT(std::abs(dp), 0.005 * dq);
  EXPECT_NEAR(u / dq, 1.0 / 3.0, 0.005);
  // d sigma_z = (C11 - C12) eps = (kn / a) eps.
  EXPECT_NEAR((s[2] - s0[2]) / b->strain()[2], l.kn / l.a, 0.01 * l.kn / l.a);
  EXPECT_LT(std::abs(b->volumetricStrain()), 1e-12);
}

// A drained triaxial step on the same lattice for contrast: with sigma_x held, the volume changes
// and p' rises by d q / 3 (so the undrained test above is not vacuous).
TEST(FccLattice, DrainedStepChangesVolumeAndMeanStress) {
  FccLattice l = fccLattice(3, 1e-3);
  auto b = lab::BoundaryControl::of(l.sim);
  l.sim.step();
  b->beginTest();
  const Vec3 s0 = b->stress();
  b->holdStress(0, s0[0]);
  b->holdStress(1, s0[1]);
  strainAxially(l.sim, *b, 2e-4, 2000);
  for (int i = 0; i < 20000; ++i) l.sim.step();  // the lateral servos settle
  const Vec3 s = b->stress();
  const double dq = (s[2] - 0.5 * (s[0] + s[1])) - (s0[2] - 0.5 * (s0[0] + s0[1]));
  EXPECT_NEAR((s.sum() - s0.sum()) / 3.0 / dq, 1.0 / 3.0, 0.02);
  EXPECT_GT(b->volumetricStrain(), 1e-5);
}

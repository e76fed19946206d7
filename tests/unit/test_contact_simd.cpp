// The vectorised [W] sphere law (core/kernels/contact_simd.hpp) against the scalar contact path, on
// every vector target this CPU supports: a jumbled scene of overlapping spheres in a box, thrown
// about for a few hundred steps so that contacts form, slide at Coulomb's limit, reach the moment
// limit, open and re-form, is stepped once with the scalar kernels and once per target, and the
// engine state (saveState: positions, velocities, spins, every contact's history and result
// slots, the energy ledger) must be the same bytes. Also: the vector path is not taken for the laws it
// does not cover.
#include <gtest/gtest.h>

#include <random>
#include <sstream>
#include <string>

#include "core/kernels/contact_simd.hpp"
#include "core/kernels/integrate_simd.hpp"
#include "core/simulation.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

namespace {

Simulation jumbledScene() {
  Simulation sim = scenes::emptyScene(6e-3, 30.0);
  sim.localDamping = 0.2;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 520; ++i) {
    const double r = 0.6e-3 * (1.0 + 0.4 * u(rng));
    sim.particles.addSphere(Vec3(u(rng), u(rng), u(rng)) * 4.5e-3, r, 2600.0);
  }
  for (std::size_t i = 0; i < sim.particles.size(); ++i) {
    sim.particles.velocity[i] = Vec3(u(rng), u(rng), u(rng)) * 0.05;
    sim.particles.angularVelocity[i] = Vec3(u(rng), u(rng), u(rng)) * 30.0;
  }
  sim.initialise();
  sim.dt = 0.2 * sim.criticalTimeStep();
  return sim;
}

// The same grains in a periodic cell sheared at a prescribed velocity gradient (image pairs, the
// flow term L l of the relative velocity, the cell's stress and stiffness sums).
Simulation jumbledCell() {
  Simulation sim = jumbledScene();
  sim.boundary = Boundary::Periodic;
  sim.cell.setBox(Vec3::Constant(9e-3));
  sim.cell.prescribedGradient = true;
  // Large enough that L l dominates the relative velocity, so that the order of its sums shows.
  sim.cell.velocityGradient << -2.0, 0.3, 5.0, 0.1, 1.0, -0.2, 0.4, 0.05, 1.0;
  sim.cell.velocityGradient *= 500.0;
  sim.initialise();
  sim.dt = 0.2 * sim.criticalTimeStep();
  return sim;
}

// The scene with [R]'s linear rolling resistance: per-grain rolling friction, combined by `rule`.
Simulation jumbledRolling(contact::CombineRule rule) {
  Simulation sim = jumbledScene();
  sim.model.rolling = contact::RollingLaw::Linear;
  sim.model.combine = rule;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> mu(0.0, 0.4);
  for (std::size_t i = 0; i < sim.particles.size(); ++i) sim.particles.rollingFriction[i] = i % 7 == 0 ? 0.0 : mu(rng);
  sim.dt = 0.2 * sim.criticalTimeStep();
  return sim;
}

enum class Scene { Box, Cell, RollingMin, RollingMean, RollingHarmonic };

std::string stateAfter(const std::string& target, int steps, Simulation* out = nullptr, Scene scene = Scene::Box) {
  kernels::selectSimdTarget(target);
  const bool cell = scene == Scene::Cell;
  Simulation sim = scene == Scene::Cell              ? jumbledCell()
                   : scene == Scene::RollingMin      ? jumbledRolling(contact::CombineRule::Min)
                   : scene == Scene::RollingMean     ? jumbledRolling(contact::CombineRule::Mean)
                   : scene == Scene::RollingHarmonic ? jumbledRolling(contact::CombineRule::Harmonic)
                                                     : jumbledScene();
  for (int s = 0; s < steps; ++s) sim.step();
  // The whole engine state as a checkpoint writes it (particles, walls or cell, every contact
  // list's history and result slots, the energy ledger, the clock).
  std::ostringstream bytes;
  sim.saveState(bytes);
  if (cell) {
    const Mat3 stress = sim.cell.stress, h = sim.cell.h;
    bytes.write(reinterpret_cast<const char*>(stress.data()), sizeof(double) * 9);
    bytes.write(reinterpret_cast<const char*>(h.data()), sizeof(double) * 9);
    bytes.write(reinterpret_cast<const char*>(sim.cell.stiffness.data()), sizeof(double) * 3);
    bytes.write(reinterpret_cast<const char*>(sim.cell.shearStiffness.data()), sizeof(double) * 3);
  }
  if (out) *out = sim;
  kernels::selectSimdTarget("best");
  return bytes.str();
}

TEST(ContactSimd, EveryTargetGivesTheScalarPathsState) {
  Simulation reference;
  const std::string scalar = stateAfter("scalar", 400, &reference);
  // The scene reaches the law's branches: sliding and yielding moments dissipate, contacts exist.
  EXPECT_GT(reference.energy.slip, 0.0);
  EXPECT_GT(reference.energy.rolling, 0.0);
  EXPECT_GT(reference.touchingPairs(), 100u);
  for (const std::string& target : kernels::simdTargetNames()) {
    if (target == "scalar") continue;
    EXPECT_TRUE(stateAfter(target, 400) == scalar) << "target " << target << ": the state differs from the scalar path's";
  }
}

TEST(ContactSimd, EveryTargetGivesTheScalarPathsStateInACell) {
  Simulation reference;
  const std::string scalar = stateAfter("scalar", 300, &reference, Scene::Cell);
  EXPECT_GT(reference.energy.slip, 0.0);
  EXPECT_GT(reference.touchingPairs(), 100u);
  std::size_t images = 0;
  for (std::size_t c = 0; c < reference.contacts.sphereSphere.size(); ++c)
    images += reference.contacts.sphereSphere.shift[c] != ImageShift::kZero && reference.contacts.sphereSphere.history[c].touching;
  EXPECT_GT(images, 5u) << "touching pairs across the cell's faces";
  EXPECT_GT(reference.cell.stress.norm(), 0.0);
  for (const std::string& target : kernels::simdTargetNames()) {
    if (target == "scalar") continue;
    EXPECT_TRUE(stateAfter(target, 300, nullptr, Scene::Cell) == scalar) << "target " << target << ": the state differs";
  }
}

// [R]'s law: bending only, Kr = Ks R^2, the limit from the two grains' rolling friction by each
// combination rule (some grains with mu_r = 0).
TEST(ContactSimd, EveryTargetGivesTheScalarPathsStateWithLinearRolling) {
  for (Scene scene : {Scene::RollingMin, Scene::RollingMean, Scene::RollingHarmonic}) {
    Simulation reference;
    const std::string scalar = stateAfter("scalar", 300, &reference, scene);
    EXPECT_GT(reference.energy.rolling, 0.0);
    for (const std::string& target : kernels::simdTargetNames()) {
      if (target == "scalar") continue;
      EXPECT_TRUE(stateAfter(target, 300, nullptr, scene) == scalar)
          << "target " << target << ", rule " << static_cast<int>(scene) << ": the state differs";
    }
  }
}

// Pairs whose centres pass through each other in one step: the next step's normal is the reverse of
// the stored one (1 + n0 . n = 0), the branch where the contact frame carries no tilt, only the
// twist. The vector lanes take it as the scalar kernel does.
TEST(ContactSimd, ReversedNormalGivesTheScalarPathsState) {
  auto run = [](const std::string& target, bool* crossed) {
    kernels::selectSimdTarget(target);
    Simulation sim = scenes::emptyScene(6e-3, 30.0);
    const int pairs = 9;
    for (int k = 0; k < pairs; ++k) {
      const double y = -4.8e-3 + 1.2e-3 * k, d = 5e-6 * (1.0 + 0.1 * k);
      sim.particles.addSphere(Vec3(-d, y, 0.0), 0.5e-3, 2600.0);
      // Even pairs on a line along x move along it: the normal turns exactly into its reverse.
      // Odd pairs are a little off the line and spin: a near reversal with a tangential history.
      sim.particles.addSphere(Vec3(d, y, k % 2 ? 1e-7 * k : 0.0), 0.5e-3, 2600.0);
    }
    sim.initialise();
    sim.dt = 0.2 * sim.criticalTimeStep();
    for (int k = 0; k < pairs; ++k) {
      // Far faster than the contact can push back: past each other within the first step.
      const double v = 1e-4 / sim.dt;
      const double off = k % 2 ? 1.0 : 0.0;
      sim.particles.velocity[2 * k] = Vec3(v, off * 0.01 * v, 0.0);
      sim.particles.velocity[2 * k + 1] = Vec3(-v, 0.0, off * 0.02 * v);
      sim.particles.angularVelocity[2 * k] = off * Vec3(0.0, 0.0, 50.0 * k);
      sim.particles.angularVelocity[2 * k + 1] = off * Vec3(20.0, 0.0, -50.0);
    }
    sim.step();
    if (crossed) {
      *crossed = sim.touchingPairs() == static_cast<std::size_t>(pairs);
      for (int k = 0; k < pairs; ++k) {
        const Vec3 a = sim.particles.position[2 * k], b = sim.particles.position[2 * k + 1];
        *crossed = *crossed && a.x() > b.x();
        if (k % 2 == 0) *crossed = *crossed && a.y() == b.y() && a.z() == 0.0 && b.z() == 0.0;  // still on the line
      }
    }
    for (int s = 0; s < 3; ++s) sim.step();
    std::ostringstream bytes;
    sim.saveState(bytes);
    kernels::selectSimdTarget("best");
    return bytes.str();
  };
  bool crossed = false;
  const std::string scalar = run("scalar", &crossed);
  ASSERT_TRUE(crossed) << "the pairs did not pass through each other in one step";
  for (const std::string& target : kernels::simdTargetNames()) {
    if (target == "scalar") continue;
    EXPECT_TRUE(run(target, nullptr) == scalar) << "target " << target << ": the state differs from the scalar path's";
  }
}

TEST(ContactSimd, TakenOnlyForTheLawItCovers) {
  contact::SphereContactModel m;  // [W]: linear, Kozicki–Donzé, [W] limit
  EXPECT_TRUE(kernels::sphereLawVectorised(m));
  contact::SphereContactModel hm = m;
  hm.law = contact::NormalLaw::HertzMindlin;
  EXPECT_FALSE(kernels::sphereLawVectorised(hm));
  contact::SphereContactModel rr = m;
  rr.rolling = contact::RollingLaw::Linear;
  EXPECT_TRUE(kernels::sphereLawVectorised(rr));
  contact::SphereContactModel none = m;
  none.rolling = contact::RollingLaw::None;
  EXPECT_FALSE(kernels::sphereLawVectorised(none));
  contact::SphereContactModel yade = m;
  yade.yadeMomentLimit = true;
  EXPECT_FALSE(kernels::sphereLawVectorised(yade));
  contact::SphereContactModel constant = m;
  constant.constantKn = 1e5;
  EXPECT_FALSE(kernels::sphereLawVectorised(constant));
  contact::SphereContactModel noMoment = m;
  noMoment.beta = 0.0;
  EXPECT_FALSE(kernels::sphereLawVectorised(noMoment));
  kernels::selectSimdTarget("scalar");
  EXPECT_FALSE(kernels::sphereLawVectorised(m));
  kernels::selectSimdTarget("best");
}

}  // namespace

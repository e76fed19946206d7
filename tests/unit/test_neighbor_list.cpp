// The Verlet list (src/core/neighbor_list.*) against brute force: no contact is ever missed.
//
// The list's promise: built at positions x0, it holds every pair closer than ra + rb + skin and
// every particle-wall pair closer than r + skin, so that after any motion of the particles and
// walls by less than skin/2 each (the rebuild threshold) every touching pair and wall contact is
// among its candidates. The first test checks this with O(N^2) brute force after random motions up
// to the threshold; the second runs a dense, fast granular gas squeezed by servo walls and counts,
// at every step, the touching contacts the engine found against brute force at the same positions.
// The neighbour list's internals are reached only through test_helpers.hpp (probe::).
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "lab/random.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

namespace {

Vec3 randomUnit(lab::Rng& rng) {
  while (true) {
    const Vec3 v(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    const double n = v.norm();
    if (n > 0.1 && n <= 1.0) return v / n;
  }
}

}  // namespace

TEST(VerletList, NoMissedContactAfterMotionUpToTheThreshold) {
  omp_set_num_threads(2);  // the list is built by two threads, each scanning a range of particles
  lab::Rng rng(21);
  Simulation sim = scenes::emptyScene(0.015);
  const std::uint32_t n = 400;
  for (std::uint32_t i = 0; i < n; ++i)
    sim.particles.addSphere(Vec3(rng.uniform(-0.014, 0.014), rng.uniform(-0.014, 0.014), rng.uniform(-0.014, 0.014)),
                            rng.uniform(1e-3, 2e-3), 2600.0);
  sim.initialise();
  probe::buildNeighbours(sim);
  const auto pairs = probe::candidatePairs(sim);
  const auto wallPairs = probe::candidateWallContacts(sim);
  const double skin = 2.0 * probe::rebuildThreshold(sim);
  ASSERT_NEAR(skin, 0.2 * 1e-3, 0.01 * skin);  // 0.2 x the smallest radius
  const auto& r = sim.particles.radius;
  const std::vector<Vec3> x0 = sim.particles.position;

  // The defining property at the build positions, by brute force (and nothing beyond the reach).
  for (std::uint32_t a = 0; a < n; ++a)
    for (std::uint32_t b = a + 1; b < n; ++b) {
      const double d = (x0[b] - x0[a]).norm();
      const bool listed = pairs.count({a, b}) > 0;
      if (d < r[a] + r[b] + 0.999 * skin) ASSERT_TRUE(listed) << a << " " << b;
      if (d > r[a] + r[b] + 1.001 * skin) ASSERT_FALSE(listed) << a << " " << b;
    }
  std::size_t near = 0;
  for (std::uint32_t a = 0; a < n; ++a)
    for (std::uint32_t b = a + 1; b < n; ++b) near += (x0[b] - x0[a]).norm() < r[a] + r[b] + skin;
  ASSERT_GT(near, 200u);  // a real test: many pairs within reach

  // Random motions of every particle and every wall by just under the threshold.
  const double step = 0.999 * probe::rebuildThreshold(sim);
  std::size_t touchingSeen = 0, wallTouchingSeen = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<Vec3> x(n);
    for (std::uint32_t i = 0; i < n; ++i) x[i] = x0[i] + step * rng.uniform() * randomUnit(rng);
    WallBox box = sim.box;
    for (Wall& w : box.walls) w.position += (w.side == 0 ? 1.0 : -1.0) * step * rng.uniform();
    for (std::uint32_t a = 0; a < n; ++a) {
      for (std::uint32_t b = a + 1; b < n; ++b) {
        const double reach = r[a] + r[b];
        if ((x[b] - x[a]).squaredNorm() < reach * reach) {
          ++touchingSeen;
          ASSERT_TRUE(pairs.count({a, b}) > 0) << "missed pair " << a << " " << b << ", trial " << trial;
        }
      }
      for (int k = 0; k < 6; ++k)
        if (box.walls[k].distance(x[a]) < r[a]) {
          ++wallTouchingSeen;
          ASSERT_TRUE(wallPairs.count({a, k}) > 0) << "missed wall contact " << a << " " << k;
        }
    }
  }
  EXPECT_GT(touchingSeen, 1000u);
  EXPECT_GT(wallTouchingSeen, 100u);
}

// A dense granular gas at a few m/s, squeezed by six stress-servoed walls: the list is rebuilt
// every few steps. At every step the engine's touching pairs and wall contacts equal brute force.
TEST(VerletList, GasUnderServoWallsMissesNoContact) {
  omp_set_num_threads(1);
  lab::Rng rng(4);
  Simulation sim = scenes::emptyScene(0.02);
  sim.model.young = 3e7;  // soft, so that a step moves the grains far (dt ~ 7e-6 s)
  const std::uint32_t n = 300;
  for (std::uint32_t i = 0; i < n; ++i) {
    sim.particles.addSphere(Vec3(rng.uniform(-0.018, 0.018), rng.uniform(-0.018, 0.018), rng.uniform(-0.018, 0.018)),
                            rng.uniform(1e-3, 1.5e-3), 2600.0);
    sim.particles.velocity.back() = 2.0 * randomUnit(rng);
    sim.particles.angularVelocity.back() = 100.0 * randomUnit(rng);
  }
  for (Wall& w : sim.box.walls) {
    w.control = WallControl::Stress;
    w.targetStress = 2e3;
  }
  sim.initialise();
  sim.dt = 0.5 * sim.criticalTimeStep();
  const auto& r = sim.particles.radius;
  std::size_t touching = 0, wallTouching = 0;
  for (int s = 0; s < 3000; ++s) {
    const std::vector<Vec3> x = sim.particles.position;
    const WallBox box = sim.box;
    sim.step();
    std::size_t pairs = 0, walls = 0;
    for (std::uint32_t a = 0; a < n; ++a) {
      for (std::uint32_t b = a + 1; b < n; ++b) {
        const double reach = r[a] + r[b];
        pairs += (x[b] - x[a]).squaredNorm() < reach * reach;
      }
      for (int k = 0; k < 6; ++k) walls += box.walls[k].distance(x[a]) < r[a];
    }
    int engineWalls = 0;
    for (const Wall& w : sim.box.walls) engineWalls += w.contacts;
    ASSERT_EQ(sim.touchingPairs(), pairs) << "step " << s;
    ASSERT_EQ(static_cast<std::size_t>(engineWalls), walls) << "step " << s;
    touching += pairs;
    wallTouching += walls;
  }
  EXPECT_GT(probe::listBuilds(sim), 100);  // rebuilt often: the test exercises the threshold
  EXPECT_GT(touching, 3000u);
  EXPECT_GT(wallTouching, 300u);
}

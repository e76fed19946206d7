// The vectorised sphere integrator (core/kernels/integrate_simd.hpp) against the scalar
// per-particle kernel (core/kernels/integrate.hpp), on every vector target this program has and
// this CPU supports: every position, velocity, spin, orientation and work term bit for bit (issue
// 25, part 2: "bit-identical between the dispatch targets"). The particles are chosen to reach
// every branch: velocities and spins of both signs and exactly zero (-0 too), particles that do not
// spin (no quaternion update), forces of both signs and zero, gravity on and off, walls and a
// periodic cell with a full flow map, and a count that leaves a tail shorter than a vector.
#include <gtest/gtest.h>

#include <cstring>
#include <ostream>
#include <random>
#include <vector>

#include "core/kernels/integrate.hpp"
#include "core/kernels/integrate_simd.hpp"
#include "core/particles.hpp"

using namespace grainlab;

namespace {

Particles randomSpheres(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, 5);
  auto value = [&](double scale) {
    switch (pick(rng)) {
      case 0: return 0.0;
      case 1: return -0.0;
      default: return scale * u(rng);
    }
  };
  Particles p;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = 1e-3 * (1.0 + 0.5 * u(rng));
    p.addSphere(Vec3(u(rng), u(rng), u(rng)) * 1e-2, r, 2650.0);
  }
  for (std::size_t i = 0; i < n; ++i) {
    p.velocity[i] = Vec3(value(0.1), value(0.1), value(0.1));
    // every third particle does not spin at all
    p.angularVelocity[i] = i % 3 == 0 ? Vec3::Zero() : Vec3(value(50.0), value(50.0), value(50.0));
    p.force[i] = Vec3(value(1.0), value(1.0), value(1.0));
    p.torque[i] = i % 3 == 0 ? Vec3::Zero() : Vec3(value(1e-3), value(1e-3), value(1e-3));
    Quat q(u(rng), u(rng), u(rng), u(rng));
    q.normalize();
    p.orientation[i] = q;
  }
  return p;
}

bool sameBits(const void* a, const void* b, std::size_t bytes) { return std::memcmp(a, b, bytes) == 0; }

void expectIdentical(const Particles& a, const Particles& b, const std::vector<kernels::ParticleWork>& wa,
                     const std::vector<kernels::ParticleWork>& wb, const std::string& what) {
  const std::size_t n = a.size();
  for (std::size_t i = 0; i < n; ++i) {
    SCOPED_TRACE(what + ", particle " + std::to_string(i));
    EXPECT_TRUE(sameBits(&a.position[i], &b.position[i], sizeof(Vec3)));
    EXPECT_TRUE(sameBits(&a.velocity[i], &b.velocity[i], sizeof(Vec3)));
    EXPECT_TRUE(sameBits(&a.angularVelocity[i], &b.angularVelocity[i], sizeof(Vec3)));
    EXPECT_TRUE(sameBits(&a.orientation[i], &b.orientation[i], sizeof(Quat)));
    EXPECT_TRUE(sameBits(&wa[i].damping, &wb[i].damping, sizeof(double)));
    EXPECT_TRUE(sameBits(&wa[i].gravity, &wb[i].gravity, sizeof(double)));
  }
}

struct Case {
  bool periodic;
  bool gravity;
  double alpha;
};
void PrintTo(const Case& c, std::ostream* os) {
  *os << (c.periodic ? "cell" : "walls") << (c.gravity ? ", gravity" : "") << ", alpha " << c.alpha;
}

class SimdTargets : public ::testing::TestWithParam<Case> {
 protected:
  void TearDown() override { kernels::selectSimdTarget("best"); }
};

TEST_P(SimdTargets, EveryTargetMatchesTheScalarKernelBitForBit) {
  const Case c = GetParam();
  kernels::IntegratorStep s;
  s.h = 3.7e-7;
  s.localDamping = c.alpha;
  s.gravity = c.gravity ? Vec3(0.3, -0.2, -9.81) : Vec3::Zero();
  s.gravityOn = c.gravity;
  if (c.periodic) {
    std::mt19937_64 rng(7);
    // A flow map far larger than a step's (|M| ~ 1e-9): M x then rounds at the size of x, so that
    // the order of the product's sums shows in the positions.
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    for (int k = 0; k < 9; ++k) s.flowStep(k / 3, k % 3) = u(rng);
  }
  // 8 lanes (AVX-512) x 4 + 5: full vectors on every target and a tail.
  const std::size_t n = 37;
  Particles reference = randomSpheres(n, 11);
  const Particles start = reference;
  // The checks: build positions near the particles, a deformation since the build (cell), a box
  // that three particles have left (walls).
  std::vector<Vec3> build(n);
  {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1e-4, 1e-4);
    for (std::size_t i = 0; i < n; ++i) build[i] = start.position[i] + Vec3(u(rng), u(rng), u(rng));
  }
  kernels::StepChecks checks;
  checks.positionsAtBuild = build.data();
  if (c.periodic) checks.deformation << 1.01, 0.02, -0.03, 0.004, 0.99, 0.05, -0.06, 0.007, 1.02;
  checks.radius = start.radius.data();
  checks.lower = Vec3(-1e-2, -1e-2, -1e-2);
  checks.upper = Vec3(1e-2, 1e-2, 1e-2);
  for (std::size_t i : {17u, 21u, 34u}) reference.position[i][i % 3] = 2e-2;  // outside (walls)
  const Particles start2 = reference;
  std::vector<kernels::ParticleWork> referenceWork(n);
  kernels::ChecksResult referenceChecks[2];
  {
    const kernels::IntegratorView view = kernels::IntegratorView::of(reference);
    for (std::size_t i = 0; i < n; ++i) {
      kernels::ChecksResult& r = referenceChecks[i < 13 ? 0 : 1];
      if (c.periodic) {
        referenceWork[i] = kernels::integrateParticle<true>(view, i, s);
        kernels::checkParticle<true>(view, i, checks, r);
      } else {
        referenceWork[i] = kernels::integrateParticle<false>(view, i, s);
        kernels::checkParticle<false>(view, i, checks, r);
      }
    }
  }
  EXPECT_EQ(referenceChecks[1].firstBad, c.periodic ? kernels::ChecksResult::kNoParticle : 17u);
  const std::vector<std::string> targets = kernels::simdTargetNames();
  ASSERT_GE(targets.size(), 3u) << "best, scalar and at least one vector target";
  for (const std::string& target : targets) {
    kernels::selectSimdTarget(target);
    Particles p = start2;
    std::vector<kernels::ParticleWork> work(n);
    const kernels::IntegratorView view = kernels::IntegratorView::of(p);
    // Two calls: one from 0, one from an offset that is not a multiple of any vector width.
    const kernels::ChecksResult r0 = kernels::integrateSpheres(view, 0, 13, s, c.periodic, work.data(), checks);
    const kernels::ChecksResult r1 = kernels::integrateSpheres(view, 13, n, s, c.periodic, work.data() + 13, checks);
    const std::string what = "target " + kernels::simdTarget();
    expectIdentical(reference, p, referenceWork, work, what);
    EXPECT_TRUE(sameBits(&r0.maxDisplacement2, &referenceChecks[0].maxDisplacement2, sizeof(double))) << what;
    EXPECT_TRUE(sameBits(&r1.maxDisplacement2, &referenceChecks[1].maxDisplacement2, sizeof(double))) << what;
    EXPECT_GT(r1.maxDisplacement2, 0.0) << what;
    EXPECT_EQ(r0.firstBad, referenceChecks[0].firstBad) << what;
    EXPECT_EQ(r1.firstBad, referenceChecks[1].firstBad) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(Integrator, SimdTargets,
                         ::testing::Values(Case{false, false, 0.3}, Case{false, true, 0.3}, Case{true, false, 0.3},
                                           Case{true, true, 0.7}, Case{false, false, 0.0}));

TEST(SimdTargets, NamesAreRefusedWithWhatIsAllowed) {
  try {
    kernels::selectSimdTarget("avx9000");
    FAIL() << "an unknown target was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("avx9000"), std::string::npos) << m;
    EXPECT_NE(m.find("scalar"), std::string::npos) << m;
  }
  kernels::selectSimdTarget("scalar");
  EXPECT_EQ(kernels::simdTarget(), "scalar");
  EXPECT_FALSE(kernels::simdEnabled());
  kernels::selectSimdTarget("best");
  EXPECT_TRUE(kernels::simdEnabled());
  EXPECT_EQ(kernels::simdTarget(), kernels::simdTargetNames()[2]) << "best is the first vector target";
}

}  // namespace

// Ellipsoids through the whole engine (pair kinds, driver, integrator, broad phase, lab), against
// independent expectations: the near-sphere limit, energy of a frictionless collision, rest on a
// wall, the simple cubic start, no missed contacts, and an exact checkpoint round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "core/contact_view.hpp"
#include "core/state_io.hpp"
#include "geometry/ellipsoid_contacts.hpp"
#include "lab/measurements.hpp"
#include "lab/protocols.hpp"
#include "lab/random.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

namespace {

Quat randomRotation(lab::Rng& rng) {
  const double u1 = rng.uniform(), u2 = 2.0 * kPi * rng.uniform(), u3 = 2.0 * kPi * rng.uniform();
  return Quat(std::sqrt(u1) * std::cos(u3), std::sqrt(1.0 - u1) * std::sin(u2), std::sqrt(1.0 - u1) * std::cos(u2),
              std::sqrt(u1) * std::sin(u3));
}

double totalEnergy(const Simulation& sim) { return lab::kineticEnergy(sim) + lab::elasticEnergy(sim); }

}  // namespace

// Grains a hair from spherical feel the sphere law: the same forces as spheres of the same
// (equivalent) radius in the same collision, to the size of the asphericity.
TEST(EllipsoidEngine, NearSphereLimitMatchesSpheres) {
  const double r = 1e-3, eps = 1e-10;  // asphericity: changes the overlap (1e-3 r) by ~eps r
  auto run = [&](bool ellipsoids) {
    Simulation sim = scenes::emptyScene();
    const Vec3 x0(-r, 0.1 * r, 0.0), x1 = x0 + (2.0 * r - 2e-6) * Vec3(1.0, -0.1, 0.05).normalized();
    if (ellipsoids) {
      const Vec3 axes(r * (1 + eps), r, r * (1 - eps));
      const double scale = r / std::cbrt(axes.prod());  // equal volume: the same equivalent radius
      sim.particles.addEllipsoid(x0, axes * scale, Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ())), 2600.0);
      sim.particles.addEllipsoid(x1, axes * scale, Quat(Eigen::AngleAxisd(1.1, Vec3::UnitY())), 2600.0);
    } else {
      sim.particles.addSphere(x0, r, 2600.0);
      sim.particles.addSphere(x1, r, 2600.0);
    }
    sim.particles.velocity[0] = Vec3(0.05, 0.01, 0.0);
    sim.particles.setAngularVelocity(1, Vec3(0.0, 3.0, 1.0));
    sim.initialise();
    sim.dt = 1e-8;
    std::vector<Vec3> force;
    for (int i = 0; i < 400; ++i) {
      sim.step();
      force.push_back(sim.particles.force[1]);
    }
    return force;
  };
  const auto spheres = run(false), ellipsoids = run(true);
  double scale = 0.0;
  for (const Vec3& f : spheres) scale = std::max(scale, f.norm());
  ASSERT_GT(scale, 0.0);
  for (std::size_t i = 0; i < spheres.size(); ++i)
    EXPECT_LT((spheres[i] - ellipsoids[i]).norm(), 1e-6 * scale) << "step " << i;
}

// Frictionless, undamped: an oblique collision of two spinning ellipsoids conserves the total energy
// (the normal force comes from a potential, torques included) and the momenta.
TEST(EllipsoidEngine, FrictionlessCollisionConservesEnergy) {
  Simulation sim = scenes::emptyScene(1.0, 0.0);
  sim.model.beta = 0.0;
  const Vec3 axes(2e-3, 1.2e-3, 0.8e-3);
  const Quat qa(Eigen::AngleAxisd(0.4, Vec3(1, 1, 0).normalized())), qb(Eigen::AngleAxisd(1.2, Vec3(0, 1, 1).normalized()));
  // B placed along an oblique line from A where the two are just apart (sqrt F = 1.01).
  const Vec3 dir = Vec3(1.0, 0.25, 0.05).normalized();
  const geometry::Sym3 xa = geometry::shapeMatrix(axes, qa), xb = geometry::shapeMatrix(axes, qb);
  double lo = 0.0, hi = 0.01;
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    (geometry::contactFunction(mid * dir, xa, xb).contactFunction < 1.0201 ? lo : hi) = mid;
  }
  sim.particles.addEllipsoid(Vec3::Zero(), axes, qa, 2600.0);
  sim.particles.addEllipsoid(hi * dir, axes, qb, 2600.0);
  sim.particles.velocity[0] = Vec3(0.5, 0.0, 0.0);
  sim.particles.velocity[1] = Vec3(-0.5, 0.05, 0.0);
  for (std::size_t i = 0; i < 2; ++i) sim.particles.setAngularVelocity(i, Vec3(20.0, -10.0, 5.0) * (i == 0 ? 1.0 : -1.0));
  sim.initialise();
  sim.dt = 0.02 * sim.criticalTimeStep();
  const double e0 = totalEnergy(sim);
  const Vec3 p0 = sim.particles.mass[0] * sim.particles.velocity[0] + sim.particles.mass[1] * sim.particles.velocity[1];
  bool touched = false;
  for (int i = 0; i < 200000; ++i) {
    sim.step();
    touched = touched || sim.touchingPairs() > 0;
    if (touched && sim.touchingPairs() == 0) break;
  }
  ASSERT_TRUE(touched);
  ASSERT_EQ(sim.touchingPairs(), 0u);
  const Vec3 p1 = sim.particles.mass[0] * sim.particles.velocity[0] + sim.particles.mass[1] * sim.particles.velocity[1];
  // Leapfrog velocities are half a step off the positions; apart, the energy is kinetic only.
  EXPECT_NEAR(totalEnergy(sim) / e0, 1.0, 1e-5);
  EXPECT_LT((p1 - p0).norm(), 1e-12 * sim.particles.mass[0]);
  // The collision changed the motion (it was not a miss).
  EXPECT_GT((sim.particles.velocity[0] - Vec3(0.5, 0.0, 0.0)).norm(), 0.01);
}

// An ellipsoid lying on the floor of a wall box under gravity settles with its short axis
// vertical at the overlap m g / kn of a wall contact (kn = 2 Ec r_eq).
TEST(EllipsoidEngine, RestsOnAWallAtTheStaticOverlap) {
  Simulation sim = scenes::emptyScene(0.01);
  sim.localDamping = 0.7;
  sim.gravity = Vec3(0, 0, -9.81);
  const Vec3 axes(3e-3, 2e-3, 1e-3);
  // Tilted a little, just above the floor at z = -0.01.
  sim.particles.addEllipsoid(Vec3(0, 0, -0.01 + 1.2e-3), axes, Quat(Eigen::AngleAxisd(0.2, Vec3::UnitX())), 2600.0);
  sim.initialise();
  sim.dt = 0.3 * sim.criticalTimeStep();
  // About 0.2 s: falling, rocking down onto the flat side, and settling (local damping).
  const long steps = std::lround(0.2 / sim.dt);
  for (long i = 0; i < steps; ++i) sim.step();
  const double kn = sim.model.wallParams(sim.particles.equivalentRadius[0], 0.0).kn;
  const double expected = sim.particles.mass[0] * 9.81 / kn;
  ASSERT_EQ(sim.contacts.ellipsoidWall.size() > 0, true);
  double overlap = 0.0;
  forEachTouchingContact(sim, [&](const ContactView& c) { overlap = c.overlap; });
  EXPECT_NEAR(overlap / expected, 1.0, 1e-3);
  const Vec3 shortAxis = sim.particles.orientation[0] * Vec3::UnitZ();
  EXPECT_GT(std::abs(shortAxis.z()), 1.0 - 1e-4);
}

// Random overlapping ellipsoids and spheres in a periodic cell: every pair the Perram–Wertheim
// function says overlaps (brute force over all pairs and images) is a touching contact.
TEST(EllipsoidEngine, NoMissedContactsAgainstBruteForce) {
  Simulation sim = scenes::emptyScene();
  sim.boundary = Boundary::Periodic;
  sim.cell.setBox(Vec3(0.02, 0.022, 0.021));
  sim.cell.prescribedGradient = true;
  lab::Rng rng(9);
  for (int i = 0; i < 120; ++i) {
    const Vec3 x = sim.cell.h * Vec3(rng.uniform(), rng.uniform(), rng.uniform());
    if (i % 4 == 0) {
      sim.particles.addSphere(x, rng.uniform(0.8e-3, 1.2e-3), 2600.0);
    } else {
      const double a = rng.uniform(1.2e-3, 2.0e-3);
      sim.particles.addEllipsoid(x, Vec3(a, a * rng.uniform(0.5, 1.0), a * rng.uniform(0.3, 0.5)), randomRotation(rng), 2600.0);
    }
  }
  sim.initialise();
  sim.dt = 1e-9;
  sim.step();
  std::set<std::pair<std::uint64_t, std::uint64_t>> found;
  forEachTouchingContact(sim, [&](const ContactView& c) {
    found.emplace(std::min(c.a, c.b), std::max(c.a, c.b));
  });
  const Particles& P = sim.particles;
  std::size_t expected = 0;
  for (std::size_t i = 0; i < P.size(); ++i)
    for (std::size_t j = i + 1; j < P.size(); ++j)
      for (int sx = -1; sx <= 1; ++sx)
        for (int sy = -1; sy <= 1; ++sy)
          for (int sz = -1; sz <= 1; ++sz) {
            const Vec3 branch = P.position[j] + sim.cell.h * Vec3(sx, sy, sz) - P.position[i];
            const auto f = geometry::contactFunction(branch, geometry::shapeMatrix(P.semiAxes[i], P.orientation[i]),
                                                     geometry::shapeMatrix(P.semiAxes[j], P.orientation[j]));
            if (f.contactFunction < 1.0) {
              ++expected;
              EXPECT_TRUE(found.count({i, j})) << "missed " << i << " " << j;
            }
          }
  EXPECT_GT(expected, 30u);
  EXPECT_EQ(found.size(), expected);
}

namespace {

lab::RunConfig latticeConfig(int n, const std::string& shape) {
  lab::RunConfig c = scenes::simpleCubicLattice(n, 25.0);  // [O]'s stiffness number 25 at 100 kPa
  c.contact.poisson = 1.0;
  if (shape == "ellipsoid") {
    c.sample.shape.type = "ellipsoid";
    c.sample.shape.elongation = 0.7;
    c.sample.shape.orientation = "aligned-x";
  }
  return c;
}

}  // namespace

// [O] §5.1: equal spheres on a simple cubic lattice, compressed isotropically: every grain touches
// its six neighbours, Z = 6 exactly, and the stress is isotropic.
TEST(EllipsoidEngine, SimpleCubicStartHasCoordinationSix) {
  lab::Laboratory lab(latticeConfig(4, "sphere"));
  const lab::PreparationResult prep = lab.prepare();
  EXPECT_EQ(lab.simulation().touchingPairs(), 3u * 64u);
  EXPECT_DOUBLE_EQ(prep.state.coordination, 6.0);
}

// Growth into aligned prolate spheroids of equal volume at constant p: the grains end with the
// asked shape and volume, long axes along x, and the sample in equilibrium at p.
TEST(EllipsoidEngine, GrowthToAlignedSpheroids) {
  lab::Laboratory lab(latticeConfig(4, "ellipsoid"));
  const lab::PreparationResult prep = lab.prepare();
  const Particles& P = lab.simulation().particles;
  for (std::size_t i = 0; i < P.size(); ++i) {
    ASSERT_EQ(P.shape[i], Shape::Ellipsoid);
    EXPECT_NEAR(P.semiAxes[i][1] / P.semiAxes[i][0], 0.7, 1e-12);
    EXPECT_NEAR(P.semiAxes[i][2], P.semiAxes[i][1], 1e-15);
    EXPECT_NEAR(std::cbrt(P.semiAxes[i].prod()), 1e-3, 1e-12);
    EXPECT_GT(std::abs((P.orientation[i] * Vec3::UnitX()).x()), 0.99);
  }
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(prep.state.boundaryStress[a] / 100e3, 1.0, 0.011);
  EXPECT_LT(prep.state.unbalanced, 0.01);
}

// A checkpoint of a state with ellipsoids continues bit for bit.
TEST(EllipsoidEngine, CheckpointContinuesBitForBit) {
  lab::Laboratory lab(latticeConfig(4, "ellipsoid"));
  lab.prepare();
  Simulation a = lab.simulation();
  a.cell.prescribedGradient = true;
  a.cell.velocityGradient = Vec3(0.2, 0.2, -0.4).asDiagonal();
  for (int i = 0; i < 50; ++i) a.step();
  std::ostringstream out(std::ios::binary);
  a.saveState(out);
  Simulation b;
  const std::string bytes = out.str();  // MemoryInput reads it in place
  stateio::MemoryInput in(bytes);
  b.loadState(in);
  b.validateState();
  for (int i = 0; i < 200; ++i) {
    a.step();
    b.step();
  }
  for (std::size_t i = 0; i < a.particles.size(); ++i) {
    EXPECT_EQ(a.particles.position[i], b.particles.position[i]);
    EXPECT_EQ(a.particles.orientation[i].coeffs(), b.particles.orientation[i].coeffs());
    EXPECT_EQ(a.particles.angularMomentum[i], b.particles.angularMomentum[i]);
  }
}

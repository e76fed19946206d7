// The step runs as one OpenMP parallel region (Simulation::step): an error found inside it (here a
// particle leaving the box, found by the integrator's per-chunk checks) must come out of step() as
// the same SimulationError for any thread count, naming the first bad particle, and leave the
// simulation usable; the clock must not advance over the failed step.
#include <gtest/gtest.h>
#include <omp.h>

#include <fmt/format.h>

#include <string>

#include "core/errors.hpp"
#include "core/pipeline.hpp"
#include "test_helpers.hpp"

using namespace grainlab;

namespace {

// 1200 spheres far apart on a lattice (more than two integrator chunks of 512), none touching.
Simulation sparseLattice() {
  Simulation sim = scenes::emptyScene(1.0);
  for (int i = 0; i < 1200; ++i) {
    const Vec3 x(-0.9 + 0.1 * (i % 19), -0.9 + 0.1 * ((i / 19) % 19), -0.9 + 0.1 * (i / 361));
    sim.particles.addSphere(x, 1e-3, 2600.0);
  }
  sim.initialise();
  sim.dt = 1e-4;
  return sim;
}

std::string stepError(Simulation& sim) {
  try {
    sim.step();
  } catch (const SimulationError& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST(EngineStep, ErrorInsideTheParallelStepNamesTheFirstBadParticle) {
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    Simulation sim = sparseLattice();
    for (int i = 0; i < 5; ++i) sim.step();
    // Two particles in different chunks (and, on two threads, on different threads) leave the box.
    sim.particles.velocity[1100] = Vec3(1e5, 0.0, 0.0);
    sim.particles.velocity[700] = Vec3(0.0, -1e5, 0.0);
    const long before = sim.stepCount;
    const std::string message = stepError(sim);
    EXPECT_NE(message.find("particle 700 left the box"), std::string::npos) << threads << " threads: " << message;
    EXPECT_NE(message.find(fmt::format("step {}", before + 1)), std::string::npos) << message;
    EXPECT_EQ(sim.stepCount, before) << "the clock stage ran after the failed integration";
    // The engine is not left in a broken state: put the grains back and the next steps run.
    sim.particles.position[1100] = sim.particles.position[700] = Vec3::Zero();
    sim.particles.velocity[1100] = sim.particles.velocity[700] = Vec3::Zero();
    sim.particles.position[700] = Vec3(0.0, 0.0, 0.5);
    EXPECT_EQ(stepError(sim), "");
    EXPECT_EQ(sim.stepCount, before + 1);
  }
  omp_set_num_threads(1);
}

// A sum over the walls and the contacts gives the same bits on one and two threads (the wall sums
// are shared out by wall, the contact loops by chunk).
TEST(EngineStep, WallSumsAreTheSameOnOneAndTwoThreads) {
  auto run = [](int threads) {
    omp_set_num_threads(threads);
    Simulation sim = scenes::emptyScene(0.010);
    sim.localDamping = 0.3;
    for (int i = 0; i < 1000; ++i) {
      const Vec3 x(-0.009 + 0.002 * (i % 10), -0.009 + 0.002 * ((i / 10) % 10), -0.009 + 0.002 * (i / 100));
      sim.particles.addSphere(x, 1.05e-3, 2600.0);  // overlapping neighbours and walls: loaded
    }
    sim.initialise();
    sim.dt = 0.2 * sim.criticalTimeStep();
    for (int i = 0; i < 200; ++i) sim.step();
    std::vector<double> out;
    for (const Wall& w : sim.box.walls) out.insert(out.end(), {w.normalForce, w.contactStiffness, double(w.contacts)});
    return out;
  };
  const std::vector<double> one = run(1), two = run(2);
  omp_set_num_threads(1);
  ASSERT_EQ(one.size(), 18u);
  EXPECT_GT(one[0], 0.0);
  EXPECT_GT(one[2], 50.0);
  for (std::size_t k = 0; k < one.size(); ++k) EXPECT_EQ(one[k], two[k]) << "term " << k;
}

// A pipeline's inner stage (Pipeline::addInside) runs inside every step right after the engine
// stage it names, once per particle, on one thread or two: here it records each particle's speed
// after "integrate" and after "boundary forces" (before the integrator moves anything), and the
// records must equal what the particles hold at those points, for both thread counts.
TEST(EngineStep, InnerStagesRunAfterTheirEngineStageForEveryParticle) {
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    Simulation sim = sparseLattice();
    for (std::size_t i = 0; i < sim.particles.size(); ++i) sim.particles.velocity[i] = Vec3(1e-3 * (i % 7), 0.0, 0.0);
    sim.gravity = Vec3(0.0, 0.0, -9.81);
    const std::size_t n = sim.particles.size();
    std::vector<double> before(n, -1.0), after(n, -1.0);
    std::vector<int> calls(n, 0);
    Pipeline pipeline(sim);
    pipeline.addInside("after integrate", "integrate", [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        after[i] = sim.particles.velocity[i].z();
        ++calls[i];
      }
    }, Simulation::kVelocities, Simulation::kLaboratory);
    pipeline.addInside("before integrate", "boundary forces", [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) before[i] = sim.particles.velocity[i].z();
    }, Simulation::kVelocities, Simulation::kLaboratory);
    std::vector<double> zBefore(n);
    pipeline.addBefore("snapshot", [&] {
      for (std::size_t i = 0; i < n; ++i) zBefore[i] = sim.particles.velocity[i].z();
    });
    pipeline.addAfter("stop", [&] {
      if (pipeline.steps() == 3) pipeline.stop();
    });
    EXPECT_EQ(pipeline.describe(),
              "snapshot -> broad phase -> contacts -> boundary forces -> before integrate -> boundary control -> "
              "integrate -> after integrate -> clock -> stop");
    EXPECT_NE(pipeline.describeAccess().find("after integrate: inside the step, shared out by particle; reads "
                                             "velocities; writes laboratory records"),
              std::string::npos)
        << pipeline.describeAccess();
    EXPECT_EQ(pipeline.run(), 3);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(calls[i], 3) << "particle " << i << " on " << threads << " threads";
      EXPECT_EQ(before[i], zBefore[i]);  // the last step's velocity before its integration
      EXPECT_EQ(after[i], sim.particles.velocity[i].z());
      EXPECT_LT(after[i], before[i]);  // gravity pulled it down in between
    }
  }
  omp_set_num_threads(1);
  Simulation sim = sparseLattice();
  Pipeline pipeline(sim);
  auto none = [](std::size_t, std::size_t) {};
  EXPECT_THROW(pipeline.addInside("late", "clock", none, 0, 0), std::invalid_argument);
  EXPECT_THROW(pipeline.addInside("nowhere", "collisions", none, 0, 0), std::invalid_argument);
}

// The engine builds its stage list from the boundary kind: a cell has no wall sums (its stress is
// summed by the contact stage), and a pipeline refuses to run once the boundary it was built for
// has changed (its inner stages are placed by index in that list).
TEST(EngineStep, StageListFollowsTheBoundaryKind) {
  auto names = [](Boundary kind) {
    std::string s;
    for (const auto& st : Simulation::engineStages(kind)) s += (s.empty() ? "" : ", ") + std::string(st.name);
    return s;
  };
  EXPECT_EQ(names(Boundary::Walls), "broad phase, contacts, boundary forces, boundary control, integrate, clock");
  EXPECT_EQ(names(Boundary::Periodic), "broad phase, contacts, boundary control, integrate, clock");
  EXPECT_EQ(Simulation::engineStageIndex(Boundary::Periodic, "integrate"), 3u);
  EXPECT_THROW(Simulation::engineStageIndex(Boundary::Periodic, "boundary forces"), std::invalid_argument);
  for (Boundary kind : {Boundary::Walls, Boundary::Periodic}) {
    int serial = 0;
    for (const auto& st : Simulation::engineStages(kind)) {
      serial += st.serial;
      EXPECT_NE(st.writes, 0u) << st.name;
    }
    EXPECT_EQ(serial, 3);  // broad phase (prepare/finish), boundary control, clock
  }
  omp_set_num_threads(1);
  Simulation sim = sparseLattice();
  Pipeline pipeline(sim);
  pipeline.addAfter("stop", [&] { pipeline.stop(); });
  sim.boundary = Boundary::Periodic;
  EXPECT_THROW(pipeline.run(), std::logic_error);
}

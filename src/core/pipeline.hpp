#pragma once
// The step as a list of named stages run in order (YADE's engine list, HOOMD's updaters): the
// engine's own stages (broad phase, contact kernels per pair kind, boundary forces and servos,
// integration, clock) and the stages a laboratory protocol adds around them (drives, load-cell
// averages, recorders, snapshots, checkpoints, stop conditions), each with a trigger. A protocol
// builds one pipeline and runs it until a stage asks to stop; `describe()` prints the order.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "core/simulation.hpp"

namespace grainlab {


// When a pipeline stage runs: every `every` steps of the run (counting from 1 after the first step's
// engine stages), and only while `when` (if given) says so.
struct StageTrigger {
  long every = 1;
  std::function<bool()> when;
  static StageTrigger always() { return {}; }
  static StageTrigger period(long n) { return {n, {}}; }
  static StageTrigger onlyIf(std::function<bool()> f) { return {1, std::move(f)}; }
};

class Pipeline {
 public:
  using Action = std::function<void()>;
  using ParticleAction = std::function<void(std::size_t begin, std::size_t end)>;
  using Trigger = StageTrigger;

  // A pipeline holding the engine stages of `sim`, in the engine's order.
  explicit Pipeline(Simulation& sim);

  // Adds a stage before the engine stages (e.g. a drive that sets boundary velocities).
  void addBefore(std::string name, Action action, Trigger trigger = {});
  // Adds a stage after everything added so far (recorders, checks).
  void addAfter(std::string name, Action action, Trigger trigger = {});
  // Adds a stage that runs inside every step, right after the engine stage `afterEngineStage`
  // (any but "clock"), on the step's threads: `body(begin, end)` handles particles [begin, end)
  // and writes only to them (Simulation::InnerStage). `reads` and `writes` are Simulation::Access
  // bits, shown by describeAccess(). E.g. a per-grain record of the velocities the integrator just
  // set, without a serial pass over all particles after the step.
  void addInside(std::string name, const std::string& afterEngineStage, ParticleAction body, unsigned reads,
                 unsigned writes);

  // Asks the run to end after the current step; later stages of this step still run unless they
  // check stopping().
  void stop() { stopping_ = true; }
  bool stopping() const { return stopping_; }
  // Steps completed in this run.
  long steps() const { return steps_; }
  // Runs steps until a stage calls stop(); returns the number of steps.
  long run();
  // The stage names in order, e.g. for the results summary and the docs.
  std::vector<std::string> names() const;
  std::string describe() const;
  // One line per stage: its name, where it runs and what it reads and writes (engine and inner
  // stages; the others run between steps and may touch anything).
  std::string describeAccess() const;

 private:
  enum class Place { Outside, Engine, Inside };
  struct Stage {
    std::string name;
    Action action;
    Trigger trigger;
    Place place;      // Engine and Inside stages run within sim_.step(), every step
    std::size_t engineIndex = 0;  // Engine: its index; Inside: the engine stage it follows
    unsigned reads = 0, writes = 0;
  };
  Simulation& sim_;
  Boundary boundary_;  // the engine stages listed are this boundary kind's
  std::vector<Stage> stages_;
  std::vector<Simulation::InnerStage> inner_;
  std::size_t firstEngine_ = 0;
  bool stopping_ = false;
  long steps_ = 0;
};

}  // namespace grainlab

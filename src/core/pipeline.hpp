#pragma once
// The step as a list of named stages run in order (YADE's engine list, HOOMD's updaters): the
// engine's own stages (broad phase, contact kernels per pair kind, boundary forces and servos,
// integration, clock) and the stages a laboratory protocol adds around them (drives, load-cell
// averages, recorders, snapshots, checkpoints, stop conditions), each with a trigger. A protocol
// builds one pipeline and runs it until a stage asks to stop; `describe()` prints the order.
#include <functional>
#include <string>
#include <vector>

namespace grainlab {

class Simulation;

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
  using Trigger = StageTrigger;

  // A pipeline holding the engine stages of `sim`, in the engine's order.
  explicit Pipeline(Simulation& sim);

  // Adds a stage before the engine stages (e.g. a drive that sets boundary velocities).
  void addBefore(std::string name, Action action, Trigger trigger = {});
  // Adds a stage after everything added so far (recorders, checks).
  void addAfter(std::string name, Action action, Trigger trigger = {});

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

 private:
  struct Stage {
    std::string name;
    Action action;
    Trigger trigger;
    bool engine;  // engine stages run every step, before the step counter advances
  };
  Simulation& sim_;
  std::vector<Stage> stages_;
  std::size_t firstEngine_ = 0;
  bool stopping_ = false;
  long steps_ = 0;
};

}  // namespace grainlab

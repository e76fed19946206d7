#include "core/pipeline.hpp"

#include <stdexcept>

namespace grainlab {

Pipeline::Pipeline(Simulation& sim) : sim_(sim), boundary_(sim.boundary) {
  const auto& engine = sim.stages();
  for (std::size_t k = 0; k < engine.size(); ++k)  // run by sim_.step()
    stages_.push_back({engine[k].name, {}, Trigger::always(), Place::Engine, k, engine[k].reads, engine[k].writes});
}

void Pipeline::addBefore(std::string name, Action action, Trigger trigger) {
  stages_.insert(stages_.begin() + static_cast<std::ptrdiff_t>(firstEngine_),
                 {std::move(name), std::move(action), std::move(trigger), Place::Outside});
  ++firstEngine_;
}

void Pipeline::addAfter(std::string name, Action action, Trigger trigger) {
  stages_.push_back({std::move(name), std::move(action), std::move(trigger), Place::Outside});
}

void Pipeline::addInside(std::string name, const std::string& afterEngineStage, ParticleAction body, unsigned reads,
                         unsigned writes) {
  const std::size_t after = Simulation::engineStageIndex(boundary_, afterEngineStage);
  // The clock ends the step without a barrier (Simulation::advanceClock): nothing may follow it.
  if (after + 1 == Simulation::engineStages(boundary_).size())
    throw std::invalid_argument("an inner stage cannot follow the engine's last stage, \"" + afterEngineStage + "\"");
  // After the engine stage and any inner stages already placed after it.
  std::size_t at = 0;
  for (std::size_t s = 0; s < stages_.size(); ++s) {
    const Stage& st = stages_[s];
    if ((st.place == Place::Engine || st.place == Place::Inside) && st.engineIndex == after) at = s + 1;
  }
  stages_.insert(stages_.begin() + static_cast<std::ptrdiff_t>(at),
                 {std::move(name), {}, Trigger::always(), Place::Inside, after, reads, writes});
  inner_.push_back({after, std::move(body)});
}

long Pipeline::run() {
  // The engine stages listed (and the inner stages placed among them) are this boundary's.
  if (sim_.boundary != boundary_)
    throw std::logic_error("Pipeline::run: the simulation's boundary changed since the pipeline was built");
  stopping_ = false;
  steps_ = 0;
  while (!stopping_) {
    // Stages before the engine see the step about to run as steps_ + 1; stages after it, the step
    // just completed: both count the same step.
    const long n = steps_ + 1;
    for (std::size_t s = 0; s < stages_.size(); ++s) {
      Stage& st = stages_[s];
      if (st.place != Place::Outside) {
        // The engine's stages, and the inner stages among them, run together as one step (one
        // parallel region, Simulation::step); they are listed one by one for describe().
        if (s == firstEngine_) {
          sim_.step(inner_.empty() ? nullptr : &inner_);
          steps_ = n;
        }
        continue;
      }
      if (st.trigger.every > 1 && n % st.trigger.every != 0) continue;
      if (st.trigger.when && !st.trigger.when()) continue;
      st.action();
    }
    steps_ = n;
  }
  return steps_;
}

std::vector<std::string> Pipeline::names() const {
  std::vector<std::string> out;
  for (const auto& s : stages_) out.push_back(s.name);
  return out;
}

std::string Pipeline::describe() const {
  std::string s;
  for (const auto& st : stages_) s += (s.empty() ? "" : " -> ") + st.name;
  return s;
}

std::string Pipeline::describeAccess() const {
  std::string s;
  for (const auto& st : stages_) {
    s += st.name;
    if (st.place == Place::Outside) {
      s += ": between steps\n";
      continue;
    }
    const bool serial = st.place == Place::Engine && Simulation::engineStages(boundary_)[st.engineIndex].serial;
    s += st.place == Place::Engine ? (serial ? ": engine, serial" : ": engine, shared out")
                                   : ": inside the step, shared out by particle";
    s += "; reads " + Simulation::accessNames(st.reads) + "; writes " + Simulation::accessNames(st.writes) + "\n";
  }
  return s;
}

}  // namespace grainlab

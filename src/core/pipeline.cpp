#include "core/pipeline.hpp"

#include "core/simulation.hpp"

namespace grainlab {

Pipeline::Pipeline(Simulation& sim) : sim_(sim) {
  for (const auto& stage : Simulation::engineStages())
    stages_.push_back({stage.name, {}, Trigger::always(), true});  // run by sim_.step()
}

void Pipeline::addBefore(std::string name, Action action, Trigger trigger) {
  stages_.insert(stages_.begin() + static_cast<std::ptrdiff_t>(firstEngine_),
                 {std::move(name), std::move(action), std::move(trigger), false});
  ++firstEngine_;
}

void Pipeline::addAfter(std::string name, Action action, Trigger trigger) {
  stages_.push_back({std::move(name), std::move(action), std::move(trigger), false});
}

long Pipeline::run() {
  stopping_ = false;
  steps_ = 0;
  while (!stopping_) {
    // Stages before the engine see the step about to run as steps_ + 1; stages after it, the step
    // just completed: both count the same step.
    const long n = steps_ + 1;
    for (std::size_t s = 0; s < stages_.size(); ++s) {
      if (s == firstEngine_ + Simulation::engineStages().size()) steps_ = n;
      Stage& st = stages_[s];
      if (st.engine) {
        // The engine's stages run together as one step (one parallel region, Simulation::step);
        // they are listed one by one for describe().
        if (s == firstEngine_) sim_.step();
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

}  // namespace grainlab

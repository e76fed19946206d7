#include <algorithm>
#include <cmath>

#include "core/simulation.hpp"

namespace grainlab {

double Simulation::criticalTimeStep() const {
  double dtc = 1e300;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const double r = particles.radius[i];
    dtc = std::min(dtc, std::sqrt(particles.mass[i] / model.maxNormalStiffness(r)));
    dtc = std::min(dtc, std::sqrt(particles.inertia[i] / model.maxRotationalStiffness(r)));
  }
  return dtc;
}

}  // namespace grainlab

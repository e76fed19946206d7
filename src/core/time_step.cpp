#include <algorithm>
#include <cmath>

#include "core/simulation.hpp"
#include "geometry/ellipsoid_time_step.hpp"

namespace grainlab {

double Simulation::criticalTimeStep() const {
  double dtc = 1e300;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    if (particles.shape[i] == Shape::Ellipsoid) {
      // Rotational stiffness of an elongated grain about each body axis (geometry/ellipsoid_time_step.hpp),
      // with the stiffest contact it can have: a wall, or a pair whose potential length frozen
      // tip to tip (2a) meets a side-by-side support sum (2c).
      const Vec3& s = particles.semiAxes[i];
      const double r = particles.equivalentRadius[i];
      const double kn = model.maxNormalStiffness(r) * std::max(1.0, geometry::potentialStiffnessFactor(s[0], s[2]));
      const double ks = model.poisson * kn;
      const double kr = (model.rolling == contact::RollingLaw::Linear ? 1.0 : model.beta) * ks * r * r;
      dtc = std::min(dtc, geometry::ellipsoidCriticalTimeStep(particles.mass[i], particles.principalInertia[i], s,
                                                              kn, ks, kr));
      continue;
    }
    const double r = particles.radius[i];
    dtc = std::min(dtc, std::sqrt(particles.mass[i] / model.maxNormalStiffness(r)));
    dtc = std::min(dtc, std::sqrt(particles.inertia[i] / model.maxRotationalStiffness(r)));
  }
  return dtc;
}

}  // namespace grainlab

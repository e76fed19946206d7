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
    if (model.hertz()) {
      // Hertz–Mindlin: also the Rayleigh time pi r sqrt(rho/G) / (0.1631 nu + 0.8766) of the grain
      // (the time a Rayleigh wave takes to cross it), besides the stiffnesses at the reference overlap.
      const double nu = model.poisson, shear = model.young / (2.0 * (1.0 + nu));
      const double rho = particles.mass[i] / (4.0 / 3.0 * kPi * r * r * r);
      dtc = std::min(dtc, kPi * r * std::sqrt(rho / shear) / (0.1631 * nu + 0.8766));
    }
    dtc = std::min(dtc, std::sqrt(particles.mass[i] / model.maxNormalStiffness(r)));
    dtc = std::min(dtc, std::sqrt(particles.inertia[i] / model.maxRotationalStiffness(r)));
  }
  return dtc;
}

}  // namespace grainlab

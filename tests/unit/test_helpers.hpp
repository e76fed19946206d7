#pragma once
// Small scenes built directly on the engine for physics tests.
#include "core/simulation.hpp"

namespace grainlab::scenes {

// An empty simulation in a large fixed box [-L, L]^3, with the [W] contact parameters and no
// damping, friction tan(mu).
inline Simulation emptyScene(double halfSide = 1.0, double frictionDeg = 30.0) {
  Simulation sim;
  sim.box.setBounds(Vec3::Constant(-halfSide), Vec3::Constant(halfSide));
  sim.model.young = 30e9;
  sim.model.poisson = 0.3;
  sim.model.tanFriction = std::tan(degToRad(frictionDeg));
  sim.model.beta = 0.15;
  sim.model.eta = 1.0;
  sim.localDamping = 0.0;
  return sim;
}

}  // namespace grainlab::scenes

#pragma once
// Small scenes built directly on the engine for physics tests, and the one place where tests reach
// below the engine's public API (the neighbour list's internals): when those change, only the
// functions in `probe` below need adapting.
#include <cstdint>
#include <set>
#include <utility>

#include "core/simulation.hpp"
#include "lab/run_config.hpp"

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

// n^3 equal spheres (d = 2 mm) on a simple cubic lattice in the periodic cell, loaded isotropically
// at the default 100 kPa with the constant normal stiffness kn = kappa p d of [O] (kappa: the
// stiffness number).
inline lab::RunConfig simpleCubicLattice(int n, double stiffnessNumber) {
  lab::RunConfig c;
  c.sample.nParticles = n * n * n;
  c.sample.method = "lattice";
  c.sample.grading.type = "uniform";
  c.sample.grading.dMin = c.sample.grading.dMax = 2e-3;
  c.sample.prepRampSteps = 2000;
  c.test.boundary = "periodic";
  c.test.type = lab::TestType::Isotropic;
  c.contact.kn = stiffnessNumber * c.test.confiningPressure * 2e-3;  // [N/m]
  return c;
}

}  // namespace grainlab::scenes

namespace grainlab::probe {

// Builds the broad-phase candidate lists for the current positions now (as the next step would).
inline void buildNeighbours(Simulation& sim) { sim.broadPhase.buildWalls(sim.particles, sim.box, sim.contacts); }

// Candidate particle pairs (a < b) of the current list.
inline std::set<std::pair<std::uint32_t, std::uint32_t>> candidatePairs(const Simulation& sim) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> out;
  const auto& pairs = sim.contacts.sphereSphere;
  for (std::size_t p = 0; p < pairs.size(); ++p) out.emplace(pairs.a[p], pairs.b[p]);
  return out;
}

// Candidate particle-wall contacts (particle, wall index 0..5) of the current list.
inline std::set<std::pair<std::uint32_t, int>> candidateWallContacts(const Simulation& sim) {
  std::set<std::pair<std::uint32_t, int>> out;
  const auto& walls = sim.contacts.sphereWall;
  for (std::size_t c = 0; c < walls.size(); ++c) out.emplace(walls.a[c], static_cast<int>(walls.b[c]));
  return out;
}

// Largest displacement of a particle (or wall) the list tolerates before a rebuild is due [m].
inline double rebuildThreshold(const Simulation& sim) { return sim.broadPhase.halfSkin(); }

// Number of times the list has been built.
inline long listBuilds(const Simulation& sim) { return sim.broadPhase.builds; }

}  // namespace grainlab::probe

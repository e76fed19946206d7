// Sample preparation (LAB.md test 1): loose placement, then compaction with a preparation friction
// (searched to meet a target e0) or frictionless radius growth, then equilibrium at full stiffness
// with the contact friction restored.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "lab/measurements.hpp"
#include "lab/placement.hpp"
#include "lab/protocols.hpp"

namespace grainlab::lab {

double Laboratory::compactWithFriction(const Simulation& loose, double muDeg, Simulation& out, long& steps) {
  sim_ = loose;
  // Rearrangement during compaction is paced by the grains' inertial time d sqrt(rho/p), not by
  // the contact stiffness; softer contacts allow a proportionally longer time step, so compaction
  // runs at Ec * prep_stiffness_factor. The packing is then stiffened to Ec and re-equilibrated.
  sim_.model.young = config_.contact.young * config_.sample.prepStiffnessFactor;
  sim_.dt = config_.solver.dtFactor * sim_.criticalTimeStep();
  sim_.localDamping = config_.sample.prepDamping;
  setFriction(muDeg);
  if (config_.sample.method == "growth") steps += growRadii();
  steps += consolidate(config_.test.confiningPressure,
                       config_.sample.method == "growth" ? std::string("equilibrium after growth")
                                                         : fmt::format("compaction (mu_prep {:.1f} deg)", muDeg));
  steps += rampStiffness();
  configureSolver(config_, sim_);
  steps += consolidate(config_.test.confiningPressure, "equilibrium at full stiffness and friction");
  out = sim_;
  return voidRatio(sim_);
}

PreparationResult Laboratory::prepare() {
  PreparationResult result;
  Rng rng(config_.sample.seed);
  const std::vector<double> diameters = sampleDiameters(config_.sample.grading, config_.sample.nParticles, rng);
  result.grading = gradingStats(diameters);
  d50_ = result.grading.d50;
  placeLoose(diameters, config_.sample.density, config_.sample.initialVoidRatio, rng, sim_);
  records_ = GrainRecords{};
  records_.sphericity = assignRollingFriction(config_, sim_.particles);
  configureSolver(config_, sim_);
  if (sim_.boundary == Boundary::Periodic) {
    const double need = sim_.broadPhase.minimumCellWidth(sim_.particles);
    // The cell shrinks to roughly (1 + e) / (1 + e_placement) of its volume; refuse up front what the
    // broad phase would refuse later.
    const double expected = sim_.cell.widths().minCoeff() * std::cbrt(1.6 / (1.0 + config_.sample.initialVoidRatio));
    if (expected < need)
      throw InputError(fmt::format(
          "config error: sample.n_particles = {}: too few for a periodic cell (its side would be ~{:.3g} m, "
          "under twice the interaction range {:.3g} m); allowed: enough particles for >= ~3 largest "
          "diameters per side", config_.sample.nParticles, expected, need));
  }
  const Simulation loose = sim_;

  const double target = config_.sample.e0;
  const double tol = config_.sample.e0Tolerance;
  Simulation best;
  double bestErr = 1e300;
  auto trial = [&](double mu) {
    Simulation out;
    const double e = compactWithFriction(loose, mu, out, result.steps);
    result.search.emplace_back(mu, e);
    if (std::abs(e - target) < bestErr) {
      bestErr = std::abs(e - target);
      best = std::move(out);
      result.prepFrictionDeg = mu;
      result.e0 = e;
    }
    return e;
  };

  if (config_.sample.method == "growth") {
    trial(0.0);  // frictionless growth: the e0 reached is the result, not a target
  } else if (config_.sample.prepFrictionDeg) {
    trial(*config_.sample.prepFrictionDeg);
  } else {
    // e(mu_prep) grows with mu_prep. Frictionless compaction gives the densest state; bracket the
    // target, then regula falsi (Illinois variant) on mu_prep.
    double muLo = 0.0, eLo = trial(0.0);
    if (target < eLo - tol)
      throw InputError(fmt::format(
          "config error: sample.e0 = {}: denser than this grading reaches (frictionless compaction "
          "gives e = {:.3f}); allowed: e0 >= {:.3f}", target, eLo, eLo - tol));
    if (bestErr > tol) {
      double muHi = 0.0, eHi = eLo;
      for (double mu : {15.0, 35.0, 60.0, 89.0}) {
        muHi = mu;
        eHi = trial(mu);
        if (eHi >= target - tol) break;
        muLo = mu;
        eLo = eHi;
      }
      if (eHi < target - tol)
        throw InputError(fmt::format(
            "config error: sample.e0 = {}: looser than this preparation reaches (mu_prep = 89 deg "
            "gives e = {:.3f}); allowed: e0 <= {:.3f}", target, eHi, eHi + tol));
      int side = 0;
      for (int it = 0; it < 10 && bestErr > tol; ++it) {
        double mu = muLo + (target - eLo) * (muHi - muLo) / (eHi - eLo);
        if (!(mu > muLo && mu < muHi)) mu = 0.5 * (muLo + muHi);
        const double e = trial(mu);
        if (e < target) {
          muLo = mu;
          eLo = e;
          if (side == -1) eHi = target + 0.5 * (eHi - target);
          side = -1;
        } else {
          muHi = mu;
          eHi = e;
          if (side == 1) eLo = target - 0.5 * (target - eLo);
          side = 1;
        }
      }
    }
  }
  sim_ = std::move(best);
  records_.reset(sim_);
  result.state = equilibriumState();
  return result;
}

PreparationResult Laboratory::adoptPacking(Simulation packed) {
  PreparationResult result;
  const Boundary expected = sim_.boundary;
  sim_ = std::move(packed);
  if (sim_.boundary != expected)
    throw InputError(fmt::format("config error: sample.packing: the packing's boundary ({}) differs from "
                                 "test.boundary = \"{}\"", sim_.boundary == Boundary::Periodic ? "periodic" : "walls",
                                 config_.test.boundary));
  records_ = GrainRecords{};
  records_.sphericity = assignRollingFriction(config_, sim_.particles);
  std::vector<double> diameters(sim_.particles.size());
  for (std::size_t i = 0; i < diameters.size(); ++i) diameters[i] = 2.0 * sim_.particles.radius[i];
  result.grading = gradingStats(diameters);
  d50_ = result.grading.d50;
  configureSolver(config_, sim_);
  result.steps = consolidate(config_.test.confiningPressure, "equilibrium of the given packing");
  result.e0 = voidRatio(sim_);
  records_.reset(sim_);
  result.state = equilibriumState();
  return result;
}

}  // namespace grainlab::lab

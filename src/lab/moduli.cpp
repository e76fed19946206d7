// Moduli as a laboratory reports them (docs/moduli.md) and the small-strain probe of a consolidated
// sample.
#include "lab/moduli.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "lab/measurements.hpp"
#include "lab/protocols.hpp"

namespace grainlab::lab {

std::optional<ElasticConstants> elasticFromIncrement(double ds1, double ds3, double de1, double de3) {
  // Unknowns a = 1/E, b = nu/E:  ds1 a - 2 ds3 b = de1,  ds3 a - (ds1 + ds3) b = de3.
  const double det = -ds1 * (ds1 + ds3) + 2.0 * ds3 * ds3;
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return std::nullopt;
  const double a = (de1 * -(ds1 + ds3) + 2.0 * ds3 * de3) / det;
  const double b = (ds1 * de3 - ds3 * de1) / det;
  if (!(a > 0.0) || !std::isfinite(a) || !std::isfinite(b)) return std::nullopt;
  // An isotropic elastic solid has -1 < nu < 1/2 (positive bulk and shear moduli); increments
  // outside are those of a structure that rearranges (a house of cards creeping during the probe).
  const double nu = b / a;
  if (!(nu > -1.0 && nu < 0.5)) return std::nullopt;
  return ElasticConstants{1.0 / a, nu};
}

std::optional<double> secantE50(const std::vector<double>& eps1, const std::vector<double>& q) {
  const std::size_t n = std::min(eps1.size(), q.size());
  if (n < 2) return std::nullopt;
  const double qPeak = *std::max_element(q.begin(), q.begin() + static_cast<long>(n));
  const double half = 0.5 * qPeak;
  if (!(half > q[0])) return std::nullopt;
  for (std::size_t i = 1; i < n; ++i) {
    if (q[i] < half) continue;
    const double f = (half - q[i - 1]) / (q[i] - q[i - 1]);
    const double e = eps1[i - 1] + f * (eps1[i] - eps1[i - 1]);
    if (!(e > eps1[0])) return std::nullopt;
    return (half - q[0]) / (e - eps1[0]);
  }
  return std::nullopt;
}

std::vector<UnloadReloadLoop> unloadReloadLoops(const std::vector<double>& eps1, const std::vector<double>& q,
                                                 const std::vector<int>& phase) {
  std::vector<UnloadReloadLoop> loops;
  const std::size_t n = std::min({eps1.size(), q.size(), phase.size()});
  for (std::size_t i = 1; i < n; ++i) {
    if ((phase[i] == 1 || phase[i] == 3) && phase[i - 1] == 0) {
      UnloadReloadLoop l;
      l.eps1Reversal = eps1[i];
      l.qReversal = l.qLoaded = q[i];
      loops.push_back(l);
    } else if (phase[i] == 1 && phase[i - 1] == 3 && !loops.empty()) {
      // The last record of the rest: the unload starts here.
      UnloadReloadLoop& l = loops.back();
      l.qReversal = q[i];
      if (l.qLoaded != 0.0) l.restRelaxation = (l.qLoaded - l.qReversal) / l.qLoaded;
    } else if (phase[i] == 2 && phase[i - 1] == 1 && !loops.empty()) {
      loops.back().eps1Turn = eps1[i];
      loops.back().qTurn = q[i];
    } else if (phase[i] == 0 && phase[i - 1] == 2 && !loops.empty()) {
      UnloadReloadLoop& l = loops.back();
      l.eps1End = eps1[i];
      l.qEnd = q[i];
      if (l.eps1End > l.eps1Turn) l.eur = (l.qEnd - l.qTurn) / (l.eps1End - l.eps1Turn);
    }
  }
  return loops;
}

ModulusProbe Laboratory::probeModuli() {
  ModulusProbe probe;
  probe.strain = config_.test.probeStrain;
  if (!(probe.strain > 0.0)) {
    probe.method = "not measured (test.probe_strain = 0)";
    return probe;
  }
  if (config_.test.type == TestType::SimpleShear) {
    probe.method = "not measured (simple shear reports its shear modulus G)";
    return probe;
  }
  // The probe runs on the consolidated sample and then puts the engine back exactly as it was: the
  // test that follows does not see it (and its results are bit-identical to a run without it).
  const Simulation saved = sim_;
  const double p = config_.test.confiningPressure;
  // Equilibrium of the probe: both states much closer to rest than the test's tolerances, since the
  // stress increment is only ~E0 * probe_strain (a few % of p for a sand, less for soft contacts).
  const long maxSteps = std::min<long>(config_.solver.maxSteps, kProbeMaxSteps);
  // Runs until the unbalanced force ratio is below kProbeUnbalanced and every controlled boundary
  // stress is within `tolerance` [Pa] of `target` (z too when `axialToo`).
  auto settle = [&](const Vec3& target, bool axialToo, double tolerance) {
    Pipeline pipeline(sim_);
    bool ok = false;
    pipeline.addAfter("probe equilibrium", [&] {
      const Vec3 s = boundaryStress(sim_);
      double dev = std::max(std::abs(s[0] - target[0]), std::abs(s[1] - target[1]));
      if (axialToo) {
        if (sim_.boundary == Boundary::Walls && sim_.gravity.squaredNorm() > 0.0) {
          // Under gravity the pedestal carries the sample's weight besides p, so the mean axial
          // stress never comes to p: judge the axial faces that hold it (as consolidate() does).
          for (int side = 0; side < 2; ++side)
            if (sim_.box.walls[WallBox::index(2, side)].control == WallControl::Stress)
              dev = std::max(dev, std::abs(sim_.box.wallStress(WallBox::index(2, side)) - target[2]));
        } else {
          dev = std::max(dev, std::abs(s[2] - target[2]));
        }
      }
      if (dev < tolerance && unbalancedForceRatio(sim_) < kProbeUnbalanced) {
        ok = true;
        pipeline.stop();
      } else if (pipeline.steps() >= maxSteps) {
        pipeline.stop();
      }
    }, Pipeline::Trigger::period(50));
    probe.steps += pipeline.run();
    return ok;
  };
  // 1. The reference state: every boundary stress at p.
  BoundaryControl& b = boundary();
  const Vec3 referenceLengths = b.referenceLengths();
  const double referenceVolume = b.referenceVolume();
  holdIsotropicStress(b, p);
  bool settled = settle(Vec3::Constant(p), true, kProbeStressTolerance * p);
  const Vec3 s0 = b.stress();
  const Vec3 l0 = b.lengths();
  // 2. The lateral boundaries now hold exactly the stresses of the reference state (each wall its
  // own), so that what the servo leaves of d_sigma3 is measured against the reference, not against p.
  const std::array<double, 6> faces = b.faceStresses();
  for (int a = 0; a < 2; ++a)
    for (int side = 0; side < 2; ++side) b.holdFaceStress(a, side, faces[WallBox::index(a, side)]);
  // 3. The axial increment, imposed at a constant rate over kProbeSteps steps; then the axis is
  // held still while the sample comes to rest.
  const double rate = probe.strain / (static_cast<double>(kProbeSteps) * sim_.dt);
  b.setReference();
  b.imposeStrainRate(2, rate);
  {
    Pipeline pipeline(sim_);
    pipeline.addAfter("probe drive", [&] {
      if (pipeline.steps() >= kProbeSteps) pipeline.stop();
    });
    probe.steps += pipeline.run();
  }
  b.fix(2);
  // The lateral stresses must come back to the reference within a small fraction of the axial
  // increment (whatever is left is corrected by elasticFromIncrement).
  const double dSigma1Driven = std::abs(boundaryStress(sim_)[2] - s0[2]);
  settled = settle(s0, false, std::max(kProbeLateralFraction * dSigma1Driven, 1e-9 * p)) && settled;
  const Vec3 s1 = b.stress();
  const Vec3 l1 = b.lengths();
  sim_ = saved;
  b.restoreReference(referenceLengths, referenceVolume);

  probe.settled = settled;
  probe.dSigma1 = s1[2] - s0[2];
  probe.dSigma3 = 0.5 * ((s1[0] - s0[0]) + (s1[1] - s0[1]));
  probe.dEps1 = (l0[2] - l1[2]) / l0[2];
  probe.dEps3 = 0.5 * ((l0[0] - l1[0]) / l0[0] + (l0[1] - l1[1]) / l0[1]);
  if (!settled) {
    probe.method = fmt::format("not measured: the probe did not come to rest within {} steps (unbalanced force "
                               "ratio < {}, lateral stress within {} of the axial increment)", maxSteps,
                               kProbeUnbalanced, kProbeLateralFraction);
    return probe;
  }
  probe.elastic = elasticFromIncrement(probe.dSigma1, probe.dSigma3, probe.dEps1, probe.dEps3);
  probe.method = probe.elastic
                     ? fmt::format("probe after consolidation: axial strain increment {:.3g} at a constant rate over {} "
                                   "steps with the lateral stresses servo-held at those of the reference state at p, then rest; E and nu "
                                   "of isotropic elasticity from the increments of boundary stress and strain (what is "
                                   "left of dsigma3 corrected)",
                                   probe.strain, kProbeSteps)
                     : std::string("not measured: the probe's increments are not those of an isotropic elastic "
                                   "solid (E <= 0 or nu outside (-1, 0.5)): the sample rearranged during the probe");
  return probe;
}

}  // namespace grainlab::lab

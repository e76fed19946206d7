// Sample preparation (docs/laboratory.md §1): loose placement, then compaction with a preparation friction
// (searched to meet a target e0) or frictionless radius growth, then equilibrium at full stiffness
// with the contact friction restored.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.hpp"
#include "lab/measurements.hpp"
#include "lab/micro_network.hpp"
#include "lab/placement.hpp"
#include "lab/protocols.hpp"
#include "geometry/ellipsoid_shape.hpp"

namespace grainlab::lab {

double Laboratory::compactWithFriction(const Simulation& loose, double muDeg, Simulation& out, long& steps) {
  sim_ = loose;
  // Rearrangement during compaction is paced by the grains' inertial time d sqrt(rho/p), not by
  // the contact stiffness; softer contacts allow a proportionally longer time step, so compaction
  // runs at Ec * prep_stiffness_factor. The packing is then stiffened to Ec and re-equilibrated.
  sim_.model.young = config_.contact.modelYoung() * config_.sample.prepStiffnessFactor;
  sim_.dt = config_.solver.dtFactor * sim_.criticalTimeStep();
  sim_.localDamping = config_.sample.prepDamping;
  setFriction(muDeg);
  if (config_.sample.method == "growth") steps += growRadii();
  if (config_.sample.method == "deposition") steps += deposit();
  if (config_.sample.method == "under-compaction") steps += underCompact();
  // "loose-moment-free": no contact moments while the skeleton forms (Kozicki–Donze: no rolling
  // stiffness; rolling-linear: no rolling friction); configureSolver() below and the saved rolling
  // friction switch them on again, from zero moment, before the full-stiffness equilibrium.
  const bool momentFree = config_.sample.method == "loose-moment-free";
  const std::vector<double> rollingFriction = sim_.particles.rollingFriction;
  if (momentFree) {
    sim_.model.beta = 0.0;
    std::fill(sim_.particles.rollingFriction.begin(), sim_.particles.rollingFriction.end(), 0.0);
  }
  const bool searched = config_.sample.method == "compaction" || momentFree;
  steps += consolidate(config_.test.confiningPressure,
                       searched ? fmt::format("compaction (mu_prep {:.1f} deg{})", muDeg, momentFree ? ", no moments" : "")
                       : config_.sample.method == "deposition" ? std::string("consolidation of the deposited bed")
                       : config_.sample.method == "under-compaction" ? std::string("consolidation of the tamped layers")
                                                               : std::string("isotropic compression"));
  // A lattice keeps its perfect symmetry through any loading (it deforms affinely); [O]'s growth
  // from the compressed lattice is not affine. sample.lattice_jitter moves every grain of the
  // compressed lattice by up to that fraction of its diameter along each axis (small beside the
  // contact overlaps, so the Z = 6 start is kept) and breaks the symmetry; spheres then relax at p
  // without friction, ellipsoids in the first stage of their growth.
  if (config_.sample.latticeJitter > 0.0) {
    Rng rng(config_.sample.seed ^ 0x9e3779b97f4a7c15ull);
    Particles& P = sim_.particles;
    for (std::size_t i = 0; i < P.size(); ++i)
      for (int a = 0; a < 3; ++a)
        P.position[i][a] += config_.sample.latticeJitter * 2.0 * P.equivalentRadius[i] * rng.uniform(-1.0, 1.0);
    sim_.initialise(config_.solver.skinFraction);
    if (config_.sample.shape.type != "ellipsoid") {
      const double friction = sim_.model.tanFriction;
      sim_.model.tanFriction = 0.0;
      steps += consolidate(config_.test.confiningPressure, "relaxation of the perturbed lattice");
      sim_.model.tanFriction = friction;
    }
  }
  if (config_.sample.shape.type == "ellipsoid") steps += growShapes();
  steps += rampStiffness();
  if (momentFree) sim_.particles.rollingFriction = rollingFriction;
  configureSolver(config_, sim_);
  steps += consolidate(config_.test.confiningPressure, "equilibrium at full stiffness and friction");
  out = sim_;
  return voidRatio(sim_);
}

PreparationResult Laboratory::prepare() {
  PreparationResult result;
  placeSample(result);
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

  if (config_.sample.method == "deposition" || config_.sample.method == "under-compaction") {
    // The grains rain and settle (and are tamped) at sample.prep_friction_deg when given, else at
    // the contact friction.
    trial(config_.sample.prepFrictionDeg.value_or(config_.contact.frictionDeg));
  } else if (config_.sample.method != "compaction" && config_.sample.method != "loose-moment-free") {
    trial(0.0);  // frictionless growth or lattice: the e0 reached is the result, not a target
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
  if (sim_.boundary == Boundary::Membrane) {
    result.steps += installMembrane();
    result.e0 = voidRatio(sim_);
  }
  result.growth = growthCurve_;
  result.deposition = deposition_;
  if (underCompaction_) {
    result.underCompaction = underCompaction_;
    result.underCompaction->preparedProfile = voidRatioProfile(underCompaction_->layers);
  }
  records_.reset(sim_);
  result.state = equilibriumState();
  result.coordination = coordination(microNetwork(sim_));
  return result;
}

void Laboratory::placeSample(PreparationResult& result) {
  Rng rng(config_.sample.seed);
  const std::vector<double> diameters = sampleDiameters(config_.sample.grading, config_.sample.nParticles, rng);
  result.grading = gradingStats(diameters);
  d50_ = result.grading.d50;
  if (config_.sample.method == "deposition") {
    // The bed's footprint is sized for a cube at e ~ 0.7 (a loose deposit); the sample is as tall as
    // its grains settle.
    const ColumnPlacement column = placeColumn(diameters, config_.sample.density, config_.sample.initialVoidRatio, 0.7,
                                               config_.sample.dropHeight, rng, sim_);
    deposition_ = DepositionReport{};
    deposition_->dropHeight = config_.sample.dropHeight;
    deposition_->cloudHeight = column.cloudHeight;
    deposition_->cloudSolidFraction = column.cloudSolidFraction;
    deposition_->width = column.width;
  } else if (config_.sample.method == "under-compaction") {
    // The footprint: the sample at its target e0 is a cube. The grains are dealt at random into
    // `layers` equal shares (each a sample of the grading), the first placed now as a cloud on the
    // floor, the others above the bed as they come (underCompact).
    std::vector<double> order = diameters;
    for (std::size_t i = order.size(); i > 1; --i)
      std::swap(order[i - 1], order[std::min(i - 1, static_cast<std::size_t>(rng.uniform() * static_cast<double>(i)))]);
    const int layers = config_.sample.layers;
    layerDiameters_.assign(layers, {});
    for (std::size_t i = 0; i < order.size(); ++i) layerDiameters_[i * layers / order.size()].push_back(order[i]);
    double solid = 0.0;
    for (double d : diameters) solid += kPi / 6.0 * d * d * d;
    const double width = std::max(std::cbrt(solid * (1.0 + config_.sample.e0)), 2.0 * *std::max_element(diameters.begin(), diameters.end()));
    sim_.particles = Particles{};
    const double h = appendSlab(layerDiameters_[0], config_.sample.density, config_.sample.initialVoidRatio, width, 0.0, rng, sim_);
    sim_.box.setBounds(Vec3::Zero(), Vec3(width, width, h));
    underCompaction_ = UnderCompactionReport{};
    underCompaction_->layers = layers;
    underCompaction_->underCompaction = config_.sample.underCompaction;
    underCompaction_->targetVoidRatio = config_.sample.e0;
    underCompaction_->width = width;
  } else if (config_.sample.method == "lattice") {
    // Equal spheres of the grading's d50 ([O]'s N = n^3 equal grains).
    const int n = static_cast<int>(std::lround(std::cbrt(static_cast<double>(config_.sample.nParticles))));
    placeLattice(n, result.grading.d50, config_.sample.density, sim_);
    result.grading = gradingStats(std::vector<double>(sim_.particles.size(), result.grading.d50));
    d50_ = result.grading.d50;
  } else if (sim_.boundary == Boundary::Membrane) {
    // The bins are sized for the compacted sample, about (1 + e0) / (1 + e_placement) of the cloud's volume.
    const double shrink = std::cbrt((1.0 + config_.sample.e0) / (1.0 + config_.sample.initialVoidRatio));
    placeCylinder(diameters, config_.sample.density, config_.sample.initialVoidRatio, config_.test.aspectRatio,
                  config_.test.membraneBinD50 * d50_, shrink, rng, sim_);
  } else {
    placeLoose(diameters, config_.sample.density, config_.sample.initialVoidRatio, rng, sim_);
  }
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
}

long Laboratory::installMembrane() {
  sim_.installFlexibleMembrane();
  return consolidate(config_.test.confiningPressure, "equilibrium in the flexible membrane");
}

long Laboratory::settle(const std::string& phase, double work0) {
  const double unbTol = config_.solver.unbalancedTolerance;
  Pipeline pipeline(sim_);
  pipeline.addAfter("settling check", [&] {
    const long steps = pipeline.steps();
    // Grains in free fall have no contact and a net force m g: the ratio is large until every
    // grain rests on the bed.
    // A violent collision in the falling cloud can make the ratio small too: the bed has settled
    // when, besides, the grains' kinetic energy is below 1e-3 of the work gravity has done.
    const double unb = unbalancedForceRatio(sim_);
    const double released = sim_.energy.gravityWork - work0;
    if (unb < unbTol && sim_.touchingPairs() > 0 && kineticEnergy(sim_) < kSettledKineticFraction * released) {
      pipeline.stop();
      return;
    }
    if (progress_ && steps % 1000 == 0)
      progress_(phase, std::clamp(1.0 - std::log10(std::max(unb / unbTol, 1.0)) / 3.0, 0.0, 0.99), steps);
    if (steps >= config_.solver.maxSteps)
      throw SimulationError(fmt::format(
          "{}: the grains have not settled after {} steps (unbalanced force ratio {:.3g}); raise solver.max_steps, "
          "lower sample.drop_height or check the parameters", phase, steps, unb));
  }, Pipeline::Trigger::period(100));
  const long steps = pipeline.run();
  if (progress_) progress_(phase, 1.0, steps);
  return steps;
}

long Laboratory::deposit() {
  // Every wall still: the grains fall from rest and settle on the floor.
  for (int a = 0; a < 3; ++a) boundary_->fix(a);
  const double work0 = sim_.energy.gravityWork;
  const long steps = settle("deposition (rain and settling)", work0);
  // The top platen comes down onto the bed's highest grain.
  const Particles& P = sim_.particles;
  double top = sim_.box.lower(2).position;
  for (std::size_t i = 0; i < P.size(); ++i) top = std::max(top, P.position[i].z() + P.radius[i]);
  sim_.box.upper(2).position = top;
  sim_.initialise(config_.solver.skinFraction);
  deposition_->bedHeight = top - sim_.box.lower(2).position;
  deposition_->settledVoidRatio = voidRatio(sim_);
  deposition_->settledCoordination = coordinationNumber(sim_);
  const MicroAnalysis bed = micro_.analyse(microNetwork(sim_));
  if (bed.ar) deposition_->settledFabricZz = bed.ar->tensor(2, 2);
  deposition_->gravityWork = sim_.energy.gravityWork - work0;
  deposition_->steps = steps;
  return steps;
}

namespace {

double bedTop(const Simulation& sim) {
  const Particles& P = sim.particles;
  double top = sim.box.lower(2).position;
  for (std::size_t i = 0; i < P.size(); ++i) top = std::max(top, P.position[i].z() + P.radius[i]);
  return top;
}

double solidVolume(const std::vector<double>& diameters) {
  double v = 0.0;
  for (double d : diameters) v += kPi / 6.0 * d * d * d;
  return v;
}

}  // namespace

std::vector<double> Laboratory::voidRatioProfile(int slices) const {
  const double z0 = sim_.box.lower(2).position, z1 = sim_.box.upper(2).position;
  const double area = sim_.box.length(0) * sim_.box.length(1);
  const double dz = (z1 - z0) / slices;
  std::vector<double> e(slices);
  for (int k = 0; k < slices; ++k) {
    const double solid = solidVolumeBetween(sim_.particles, z0 + k * dz, z0 + (k + 1) * dz);
    e[k] = solid > 0.0 ? area * dz / solid - 1.0 : std::numeric_limits<double>::infinity();
  }
  return e;
}

long Laboratory::underCompact() {
  UnderCompactionReport& r = *underCompaction_;
  const int layers = r.layers;
  const double area = r.width * r.width;
  const double floor = sim_.box.lower(2).position;
  const double work0 = sim_.energy.gravityWork;
  // The clouds of layers 2..L: a stream of their own (the first layer's came from placeSample's).
  Rng rng(config_.sample.seed ^ 0x2545f4914f6cdd1dull);
  Wall& platen = sim_.box.upper(2);
  double target = floor;
  double below = floor;  // the top of the layers below at the target density
  double solidSoFar = 0.0;
  long steps = 0;
  for (int k = 0; k < layers; ++k) {
    const double solid = solidVolume(layerDiameters_[k]);
    solidSoFar += solid;
    // Ladd (1978): layer k (0 = the bottom) is tamped to a dry density (1 - U_k) times the
    // target's, U_k falling linearly from U at the bottom to 0 at the top, on the layers below
    // taken at the target density: tamping layer k compacts the layers below it further, which
    // their under-compaction anticipates. The last layer (U = 0) ends the stack at e0.
    const double u = r.underCompaction * static_cast<double>(layers - 1 - k) / static_cast<double>(layers - 1);
    target = below + solid * (1.0 + r.targetVoidRatio) / (1.0 - u) / area;
    below += solid * (1.0 + r.targetVoidRatio) / area;
    if (k > 0) {
      // The platen is lifted and the next cloud placed above the bed.
      const double top = bedTop(sim_);
      const double h = appendSlab(layerDiameters_[k], config_.sample.density, config_.sample.initialVoidRatio, r.width, top,
                                  rng, sim_);
      platen.position = top + h;
      sim_.initialise(config_.solver.skinFraction);
      sim_.dt = config_.solver.dtFactor * sim_.criticalTimeStep();
    }
    for (int a = 0; a < 3; ++a) boundary_->fix(a);
    const double travel = platen.position - target;
    if (travel > 0.0) {
      // The tamper: the top platen at a constant speed, kTampSteps steps from the cloud's top to
      // the target height, where it stops.
      r.tamperSpeed = travel / (static_cast<double>(kTampSteps) * sim_.dt);
      platen.control = WallControl::Velocity;
      platen.velocity = -r.tamperSpeed;
      Pipeline pipeline(sim_);
      // The tamping effort is capped at the confining pressure p: a layer the platen cannot bring to
      // its height without pushing harder than p stays looser (reported), instead of being
      // over-consolidated by a stress the test never applies (and springing back from it).
      const double cap = config_.test.confiningPressure;
      const int topFace = WallBox::index(2, 1);
      pipeline.addAfter("tamper", [&] {
        if (platen.position <= target || sim_.box.wallStress(topFace) > cap) {
          platen.control = WallControl::Fixed;
          platen.velocity = 0.0;
          pipeline.stop();
        }
      }, Pipeline::Trigger::period(1));
      steps += pipeline.run();
    }
    r.tamperStress.push_back(sim_.box.wallStress(WallBox::index(2, 1)));
    r.tamperReached.push_back(platen.position <= target);
    steps += settle(fmt::format("under-compaction: layer {}/{} tamped, settling", k + 1, layers), work0);
    r.targetHeights.push_back(target - floor);
    r.tampedVoidRatio.push_back(area * (bedTop(sim_) - floor) / solidSoFar - 1.0);
  }
  // The grains of every layer in place: rolling friction per grain for all of them (the first
  // assignment saw the first layer only), and the platen down onto the bed's highest grain.
  records_.sphericity = assignRollingFriction(config_, sim_.particles);
  platen.position = bedTop(sim_);
  sim_.initialise(config_.solver.skinFraction);
  r.voidRatio = voidRatio(sim_);
  r.coordination = coordinationNumber(sim_);
  const MicroAnalysis bed = micro_.analyse(microNetwork(sim_));
  if (bed.ar) r.fabricZz = bed.ar->tensor(2, 2);
  r.voidRatioProfile = voidRatioProfile(layers);
  r.gravityWork = sim_.energy.gravityWork - work0;
  r.steps = steps;
  return steps;
}

long Laboratory::growShapes() {
  const ShapeConfig& shape = config_.sample.shape;
  const double density = config_.sample.density;
  const double pressure = config_.test.confiningPressure;
  Particles& P = sim_.particles;
  const std::size_t n = P.size();
  // Which grains grow, and their orientations: a stream of their own, so that the grading and the
  // placement do not change with the shape.
  Rng rng(config_.sample.seed ^ 0x5851f42d4c957f2dull);
  std::vector<char> grows(n);
  std::vector<Quat> orientation(n, Quat::Identity());
  for (std::size_t i = 0; i < n; ++i) {
    grows[i] = shape.fraction >= 1.0 || rng.uniform() < shape.fraction;
    if (shape.orientation == "random") {
      // A uniformly random rotation (Shoemake 1992).
      const double u1 = rng.uniform(), u2 = 2.0 * kPi * rng.uniform(), u3 = 2.0 * kPi * rng.uniform();
      orientation[i] = Quat(std::sqrt(u1) * std::cos(u3), std::sqrt(1.0 - u1) * std::sin(u2),
                            std::sqrt(1.0 - u1) * std::cos(u2), std::sqrt(u1) * std::sin(u3));
    }
  }
  std::vector<double> radius0(n);
  for (std::size_t i = 0; i < n; ++i) radius0[i] = P.equivalentRadius[i];
  growthCurve_.clear();
  auto recordStage = [&](double e) {
    const std::vector<int> z = contactsPerParticle(sim_);
    double mean = 0.0, square = 0.0;
    for (int c : z) mean += c;
    mean /= static_cast<double>(n);
    for (int c : z) square += (c - mean) * (c - mean);
    growthCurve_.push_back({e, mean, std::sqrt(square / static_cast<double>(n)), 1.0 / (1.0 + voidRatio(sim_))});
  };
  recordStage(0.0);
  // Eccentricity (a - b)/(a + b) of the final shape, reached in equal steps of at most
  // eccentricity_step; the flatness goes from 1 to its final value in the same steps.
  const double eFinal = (1.0 - shape.elongation) / (1.0 + shape.elongation);
  const int stages = std::max(1, static_cast<int>(std::ceil(std::max(eFinal, 1.0 - shape.flatness) / shape.eccentricityStep - 1e-9)));
  const double friction = sim_.model.tanFriction;
  sim_.model.tanFriction = 0.0;  // [O]: grains grow without friction
  long steps = 0;
  for (int k = 1; k <= stages; ++k) {
    const double f = static_cast<double>(k) / stages;
    const double e = f * eFinal;
    const double elr = (1.0 - e) / (1.0 + e), flr = 1.0 + f * (shape.flatness - 1.0);
    for (std::size_t i = 0; i < n; ++i) {
      if (!grows[i]) continue;
      if (k == 1) P.orientation[i] = orientation[i];
      P.setShape(i, geometry::semiAxesFromOuadfel(radius0[i], elr, flr), density);
    }
    // New sizes: new skin and lists; the critical step falls as the grains elongate.
    sim_.initialise(config_.solver.skinFraction);
    sim_.dt = config_.solver.dtFactor * sim_.criticalTimeStep();
    steps += consolidate(pressure, fmt::format("shape growth {}/{} (eccentricity {:.3f})", k, stages, e));
    recordStage(e);
  }
  sim_.model.tanFriction = friction;
  return steps;
}

void Laboratory::checkSample(const Simulation* packed) {
  if (!packed) {
    PreparationResult result;
    placeSample(result);
    return;
  }
  sim_ = *packed;
  assignRollingFriction(config_, sim_.particles);
  std::vector<double> diameters(sim_.particles.size());
  for (std::size_t i = 0; i < diameters.size(); ++i) diameters[i] = 2.0 * sim_.particles.equivalentRadius[i];
  d50_ = gradingStats(diameters).d50;
  configureSolver(config_, sim_);
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
  for (Shape s : sim_.particles.shape) microColumns_.nonSpherical = microColumns_.nonSpherical || s == Shape::Ellipsoid;
  std::vector<double> diameters(sim_.particles.size());
  // Equivalent (equal-volume) diameters: the grading and d50 of ellipsoids are those of their volumes.
  for (std::size_t i = 0; i < diameters.size(); ++i) diameters[i] = 2.0 * sim_.particles.equivalentRadius[i];
  result.grading = gradingStats(diameters);
  d50_ = result.grading.d50;
  configureSolver(config_, sim_);
  result.steps = 0;
  if (config_.sample.packingFrictionDeg) {
    // [O]'s unloading to a lower pressure: the packing goes to the test's pressure at this friction
    // (0: grains slide freely, as in [O]), then the test's friction is restored.
    const double friction = sim_.model.tanFriction;
    sim_.model.tanFriction = std::tan(degToRad(*config_.sample.packingFrictionDeg));
    result.steps += consolidate(config_.test.confiningPressure,
                                fmt::format("the given packing to p at friction {} deg", *config_.sample.packingFrictionDeg));
    sim_.model.tanFriction = friction;
  }
  result.steps += consolidate(config_.test.confiningPressure, "equilibrium of the given packing");
  result.e0 = voidRatio(sim_);
  records_.reset(sim_);
  result.state = equilibriumState();
  result.coordination = coordination(microNetwork(sim_));
  return result;
}

}  // namespace grainlab::lab

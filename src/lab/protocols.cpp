#include "lab/protocols.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "lab/macro.hpp"
#include "lab/measurements.hpp"
#include "lab/placement.hpp"
#include "core/state_io.hpp"
#include "lab/sphericity.hpp"

namespace grainlab::lab {

void configureSolver(const RunConfig& c, Simulation& sim) {
  sim.model.young = c.contact.young;
  sim.model.poisson = c.contact.poisson;
  sim.model.beta = c.contact.beta;
  sim.model.eta = c.contact.eta;
  sim.model.rolling = c.contact.model == "rolling-linear" ? contact::RollingLaw::Linear
                                                          : contact::RollingLaw::KozickiDonze;
  if (c.contact.sphericity) {
    const std::string& rule = c.contact.sphericity->combine;
    sim.model.combine = rule == "mean"       ? contact::CombineRule::Mean
                        : rule == "harmonic" ? contact::CombineRule::Harmonic
                                             : contact::CombineRule::Min;
  }
  sim.model.tanFriction = std::tan(degToRad(c.contact.frictionDeg));
  for (Wall& w : sim.box.walls) w.tanFriction = std::tan(degToRad(c.contact.wallFrictionDeg));
  sim.localDamping = c.solver.damping;
  sim.servo.gain = c.solver.servoGain;
  sim.servo.integralSteps = c.solver.servoIntegralSteps;
  sim.servo.maxSpeed = c.solver.servoMaxSpeed;
  sim.initialise(c.solver.skinFraction);
  const double dtc = sim.criticalTimeStep();
  if (c.solver.dt) {
    if (*c.solver.dt > dtc && !c.solver.forceDt)
      throw InputError(fmt::format(
          "config error: solver.dt = {:.6g}: above the critical time step {:.6g} s of this sample; "
          "allowed: dt <= {:.6g} (or solver.force_dt = true)", *c.solver.dt, dtc, dtc));
    sim.dt = *c.solver.dt;
  } else {
    sim.dt = c.solver.dtFactor * dtc;
  }
}

Laboratory::Laboratory(const RunConfig& config, ProgressFn progress)
    : config_(config), progress_(std::move(progress)) {}

EquilibriumState Laboratory::equilibriumState() const {
  return {wallStress(sim_), contactStress(sim_), unbalancedForceRatio(sim_), voidRatio(sim_)};
}

long Laboratory::consolidate(double pressure, const std::string& phase) {
  for (Wall& w : sim_.box.walls) {
    w.control = WallControl::Stress;
    w.targetStress = pressure;
  }
  const int checkEvery = 100;
  const double stressTol = config_.solver.stressTolerance;
  const double unbTol = config_.solver.unbalancedTolerance;
  long steps = 0;
  double worst = 1.0;
  while (true) {
    sim_.step();
    ++steps;
    if (steps % checkEvery != 0) continue;
    const Vec3 s = wallStress(sim_);
    double dev = 0.0;
    for (int a = 0; a < 3; ++a) dev = std::max(dev, std::abs(s[a] - pressure) / pressure);
    const double unb = unbalancedForceRatio(sim_);
    if (dev < stressTol && unb < unbTol) break;
    // Progress: how far the worse of the two criteria is from its tolerance, on a log scale.
    worst = std::max(dev / stressTol, unb / unbTol);
    if (progress_ && steps % (10 * checkEvery) == 0)
      progress_(phase, std::clamp(1.0 - std::log10(std::max(worst, 1.0)) / 3.0, 0.0, 0.99), steps);
    if (steps >= config_.solver.maxSteps)
      throw SimulationError(fmt::format(
          "{}: no equilibrium after {} steps (stress off target by {:.3g} %, unbalanced force ratio "
          "{:.3g}); raise solver.max_steps or check the parameters", phase, steps, 100.0 * dev, unb));
  }
  if (progress_) progress_(phase, 1.0, steps);
  return steps;
}

double Laboratory::compactWithFriction(const Simulation& loose, double muDeg, Simulation& out,
                                       long& steps) {
  sim_ = loose;
  // Rearrangement during compaction is paced by the grains' inertial time d sqrt(rho/p), not by
  // the contact stiffness; softer contacts allow a proportionally longer time step, so compaction
  // runs at Ec * prep_stiffness_factor. The packing is then stiffened to Ec and re-equilibrated.
  sim_.model.young = config_.contact.young * config_.sample.prepStiffnessFactor;
  sim_.dt = config_.solver.dtFactor * sim_.criticalTimeStep();
  sim_.localDamping = config_.sample.prepDamping;
  setFriction(muDeg);
  steps += consolidate(config_.test.confiningPressure, fmt::format("compaction (mu_prep {:.1f} deg)", muDeg));
  steps += rampStiffness();
  configureSolver(config_, sim_);
  steps += consolidate(config_.test.confiningPressure, "equilibrium at full stiffness and friction");
  out = sim_;
  return voidRatio(sim_);
}

long Laboratory::rampStiffness() {
  // A sudden stiffening would multiply every contact force by 1/factor at once and blow the packing
  // apart; a geometric ramp lets the wall servos follow as the overlaps shrink.
  const double factor = config_.sample.prepStiffnessFactor;
  if (factor >= 1.0) return 0;
  const long rampSteps = config_.sample.prepRampSteps;
  const double growth = std::pow(1.0 / factor, 1.0 / static_cast<double>(rampSteps));
  const double dtFromYoung = sim_.dt * std::sqrt(sim_.model.young);  // dt scales as Ec^-1/2
  for (long i = 0; i < rampSteps; ++i) {
    sim_.model.young = std::min(config_.contact.young, sim_.model.young * growth);
    sim_.dt = dtFromYoung / std::sqrt(sim_.model.young);
    sim_.step();
    if (progress_ && i % 1000 == 0) progress_("stiffness ramp", static_cast<double>(i) / rampSteps, i);
  }
  return rampSteps;
}

void assignRollingFriction(const RunConfig& c, Particles& particles) {
  if (c.contact.model != "rolling-linear") return;
  const std::size_t n = particles.size();
  if (!c.contact.sphericity) {
    particles.rollingFriction.assign(n, c.contact.rollingFriction);
    particles.sphericity.assign(n, 1.0);
    return;
  }
  const SphericityConfig& sc = *c.contact.sphericity;
  const SphericityDistribution d = readSphericityFile(sc.file, "contact.sphericity.file");
  // A stream of its own, so that giving grains a sphericity does not change the sample's grading.
  Rng rng(c.sample.seed ^ 0x9e3779b97f4a7c15ull);
  particles.sphericity = sampleSphericity(d, n, rng);
  particles.rollingFriction.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    particles.rollingFriction[i] = rollingFrictionFromSphericity(particles.sphericity[i], sc.c, sc.k);
}

PreparationResult Laboratory::prepare() {
  PreparationResult result;
  Rng rng(config_.sample.seed);
  const std::vector<double> diameters =
      sampleDiameters(config_.sample.grading, config_.sample.nParticles, rng);
  result.grading = gradingStats(diameters);
  d50_ = result.grading.d50;
  placeLoose(diameters, config_.sample.density, config_.sample.initialVoidRatio, rng,
             sim_.particles, sim_.box);
  assignRollingFriction(config_, sim_.particles);
  configureSolver(config_, sim_);
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

  if (config_.sample.prepFrictionDeg) {
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
  result.state = equilibriumState();
  return result;
}

PreparationResult Laboratory::adoptPacking(Simulation packed) {
  PreparationResult result;
  sim_ = std::move(packed);
  assignRollingFriction(config_, sim_.particles);
  std::vector<double> diameters(sim_.particles.size());
  for (std::size_t i = 0; i < diameters.size(); ++i) diameters[i] = 2.0 * sim_.particles.radius[i];
  result.grading = gradingStats(diameters);
  d50_ = result.grading.d50;
  configureSolver(config_, sim_);
  result.steps = consolidate(config_.test.confiningPressure, "equilibrium of the given packing");
  result.prepFrictionDeg = config_.contact.frictionDeg;
  result.e0 = voidRatio(sim_);
  result.state = equilibriumState();
  return result;
}

GrainKinematics Laboratory::currentKinematics() const {
  // Before shearing the reference is the current state; lengths are those of the box then.
  const Vec3 l0 = shearReference_ ? *shearReference_
                                  : Vec3(sim_.box.length(0), sim_.box.length(1), sim_.box.length(2));
  Mat3 boxStrain = Mat3::Zero();
  for (int a = 0; a < 3; ++a) {
    const double stretch = sim_.box.length(a) / l0[a];
    boxStrain(a, a) = 0.5 * (stretch * stretch - 1.0);
  }
  // Grains with at least two contacts (walls included) carry load; the others are rattlers.
  const std::vector<int> contacts = contactsPerParticle(sim_);
  std::vector<char> active(contacts.size());
  for (std::size_t i = 0; i < contacts.size(); ++i) active[i] = contacts[i] >= 2;
  return grainKinematics(sim_.particles, sim_.particles.referencePosition, boxStrain,
                         kNeighbourhoodDiameters * d50_, config_.output.bandFactor, active);
}

Record Laboratory::measure(double h0, double v0, const Vec3& l0, double strainRate,
                           const Vec3* meanStress) const {
  Record r;
  r.step = sim_.stepCount;
  r.time = sim_.time;
  const WallBox& b = sim_.box;
  r.eps1 = (h0 - b.length(2)) / h0;
  r.eps2 = (l0[0] - b.length(0)) / l0[0];
  r.eps3 = (l0[1] - b.length(1)) / l0[1];
  r.epsV = (v0 - b.volume()) / v0;
  const Vec3 s = meanStress ? *meanStress : wallStress(sim_);
  r.sigma1 = s[2];
  r.sigma2 = s[0];
  r.sigma3 = s[1];
  const double lateral = 0.5 * (r.sigma2 + r.sigma3);
  r.q = r.sigma1 - lateral;
  r.p = (r.sigma1 + r.sigma2 + r.sigma3) / 3.0;
  r.e = voidRatio(sim_);
  r.phiDeg = mobilisedFrictionDeg(r.sigma1, lateral);
  r.coordination = coordinationNumber(sim_);
  r.unbalanced = unbalancedForceRatio(sim_);
  r.inertialNumber = strainRate * d50_ * std::sqrt(config_.sample.density / std::max(r.p, 1e-300));
  const Mat3 sc = contactStress(sim_);
  r.sigma1Contact = sc(2, 2);
  r.sigma2Contact = sc(0, 0);
  r.sigma3Contact = sc(1, 1);
  const GrainKinematics k = currentKinematics();
  r.rotationMeanDeg = k.rotationMeanDeg;
  r.rotationBandMeanDeg = k.rotationBandMeanDeg;
  r.bandFraction = k.bandFraction;
  r.kinetic = kineticEnergy(sim_);
  r.elastic = elasticEnergy(sim_);
  r.workBoundary = sim_.energy.boundaryWork;
  r.dissipSlip = sim_.energy.slip;
  r.dissipRoll = sim_.energy.rolling;
  r.dissipDamping = sim_.energy.damping;
  return r;
}

void Laboratory::beginShear() {
  ShearState& st = shear_;
  st = ShearState{};
  const double p = config_.test.confiningPressure;
  const double rho = config_.sample.density;
  setFriction(config_.contact.frictionDeg);
  // "auto": the fastest rate with inertial number I = rate d50 sqrt(rho/p) <= 1e-3, aimed at
  // kAutoInertialNumber (2 % below the limit) so that the servo's small dips of p stay under it.
  st.result.strainRate =
      config_.test.axialStrainRate.value_or(kAutoInertialNumber / (d50_ * std::sqrt(rho / p)));
  st.result.inertialNumber = st.result.strainRate * d50_ * std::sqrt(rho / p);

  WallBox& box = sim_.box;
  st.h0 = box.length(2);
  st.v0 = box.volume();
  st.l0 = Vec3(box.length(0), box.length(1), box.length(2));
  for (int a = 0; a < 2; ++a)
    for (int side = 0; side < 2; ++side) {
      Wall& w = box.walls[WallBox::index(a, side)];
      w.control = WallControl::Stress;
      w.targetStress = p;
    }
  // Platens at constant speed: engineering axial strain rate on the initial height. The speed is
  // ramped up linearly over kPlatenRampIntegralTimes servo integral times, so that the lateral
  // servos learn how fast their walls must move instead of lagging behind a sudden start (with the
  // stiff contacts of [W] sigma1 rises by several times p within 0.05 % of axial strain).
  st.platenSpeed = 0.5 * st.result.strainRate * st.h0;
  st.rampSteps = std::max(1L, static_cast<long>(kPlatenRampIntegralTimes * config_.solver.servoIntegralSteps));
  box.lower(2).control = WallControl::Velocity;
  box.upper(2).control = WallControl::Velocity;
  sim_.particles.resetKinematicReference();
  shearReference_ = st.l0;
  sim_.energy = EnergyLedger{};

  st.result.records.push_back(measure(st.h0, st.v0, st.l0, st.result.strainRate));
  // Records are ten times denser below 1 % axial strain, where E and nu are measured.
  const double every = config_.output.recordEveryStrain;
  st.nextRecord = std::min(every, 0.1 * every);
  st.nextSnapshot = snapshotEvery_;
  st.nextCheckpoint = checkpointEvery_;
  st.startStep = sim_.stepCount;
  st.started = true;
  if (snapshot_) snapshot_(sim_, 0.0);
}

ShearResult Laboratory::continueShear() {
  ShearState& st = shear_;
  const double p = config_.test.confiningPressure;
  const double finalStrain = config_.test.finalAxialStrain;
  const double every = config_.output.recordEveryStrain;
  WallBox& box = sim_.box;
  while (true) {
    const double ramp = std::min(1.0, static_cast<double>(sim_.stepCount - st.startStep + 1) / st.rampSteps);
    box.lower(2).velocity = ramp * st.platenSpeed;
    box.upper(2).velocity = -ramp * st.platenSpeed;
    sim_.step();
    st.stressSum += wallStress(sim_);
    ++st.stressSamples;
    const double eps1 = (st.h0 - box.length(2)) / st.h0;
    const bool last = eps1 >= finalStrain;
    if (eps1 >= st.nextRecord || last) {
      const Vec3 meanStress = st.stressSum / static_cast<double>(st.stressSamples);
      st.stressSum.setZero();
      st.stressSamples = 0;
      Record r = measure(st.h0, st.v0, st.l0, st.result.strainRate, &meanStress);
      st.result.maxLateralDeviation = std::max(
          {st.result.maxLateralDeviation, std::abs(r.sigma2 - p) / p, std::abs(r.sigma3 - p) / p});
      st.result.records.push_back(r);
      while (st.nextRecord <= eps1) st.nextRecord += eps1 < 0.01 ? 0.1 * every : every;
    }
    if (snapshot_ && snapshotEvery_ > 0.0 && (eps1 >= st.nextSnapshot || last)) {
      snapshot_(sim_, eps1);
      while (st.nextSnapshot <= eps1) st.nextSnapshot += snapshotEvery_;
    }
    if (progress_ && (sim_.stepCount - st.startStep) % 2000 == 0)
      progress_("triaxial shearing", std::min(1.0, eps1 / finalStrain), sim_.stepCount - st.startStep);
    if (last) break;
    // Checkpoints between steps, after the step's records and snapshots: a resumed run repeats none.
    if (checkpoint_ && checkpointEvery_ > 0.0 && eps1 >= st.nextCheckpoint) {
      while (st.nextCheckpoint <= eps1) st.nextCheckpoint += checkpointEvery_;
      checkpoint_(*this);
    }
    if (sim_.stepCount - st.startStep >= config_.solver.maxSteps)
      throw SimulationError(fmt::format("triaxial shearing: reached solver.max_steps = {} at eps1 = {:.4f}",
                                        config_.solver.maxSteps, eps1));
  }
  if (progress_) progress_("triaxial shearing", 1.0, sim_.stepCount - st.startStep);
  st.result.steps = sim_.stepCount - st.startStep;
  return st.result;
}

ShearResult Laboratory::shear() {
  beginShear();
  return continueShear();
}

void Laboratory::saveState(std::ostream& out) const {
  using namespace stateio;
  sim_.saveState(out);
  put(out, d50_);
  const bool hasReference = shearReference_.has_value();
  put(out, hasReference);
  put(out, hasReference ? *shearReference_ : Vec3::Zero().eval());
  const ShearState& st = shear_;
  put(out, st.started);
  put(out, st.h0);
  put(out, st.v0);
  put(out, st.l0);
  put(out, st.platenSpeed);
  put(out, st.rampSteps);
  put(out, st.startStep);
  put(out, st.nextRecord);
  put(out, st.nextSnapshot);
  put(out, st.nextCheckpoint);
  put(out, st.stressSum);
  put(out, st.stressSamples);
  put(out, st.result.strainRate);
  put(out, st.result.inertialNumber);
  put(out, st.result.maxLateralDeviation);
  putVector(out, st.result.records);
}

void Laboratory::loadState(std::istream& in) {
  using namespace stateio;
  sim_.loadState(in);
  get(in, d50_);
  bool hasReference = false;
  Vec3 reference;
  get(in, hasReference);
  get(in, reference);
  shearReference_.reset();
  if (hasReference) shearReference_ = reference;
  ShearState& st = shear_;
  get(in, st.started);
  get(in, st.h0);
  get(in, st.v0);
  get(in, st.l0);
  get(in, st.platenSpeed);
  get(in, st.rampSteps);
  get(in, st.startStep);
  get(in, st.nextRecord);
  get(in, st.nextSnapshot);
  get(in, st.nextCheckpoint);
  get(in, st.stressSum);
  get(in, st.stressSamples);
  get(in, st.result.strainRate);
  get(in, st.result.inertialNumber);
  get(in, st.result.maxLateralDeviation);
  getVector(in, st.result.records);
}

}  // namespace grainlab::lab

#include "lab/protocols.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "core/state_io.hpp"
#include "lab/measurements.hpp"
#include "io/input_file.hpp"
#include "lab/sphericity.hpp"

namespace grainlab::lab {

void configureSolver(const RunConfig& c, Simulation& sim) {
  sim.model.young = c.contact.modelYoung();
  sim.model.poisson = c.contact.poisson;
  sim.model.beta = c.contact.beta;
  sim.model.eta = c.contact.eta;
  const std::string& slot = c.contact.rollingSlot();
  sim.model.rolling = slot == "rolling-linear" ? contact::RollingLaw::Linear
                      : slot == "none"         ? contact::RollingLaw::None
                                               : contact::RollingLaw::KozickiDonze;
  sim.model.law = c.contact.hertz() ? contact::NormalLaw::HertzMindlin : contact::NormalLaw::Linear;
  sim.model.restitutionBeta = c.contact.hertz() ? contact::restitutionDampingRatio(c.contact.restitution) : 0.0;
  sim.model.referenceStress = c.contact.hertz() ? c.test.largestStress() : 0.0;
  if (c.contact.sphericity) {
    const std::string& rule = c.contact.sphericity->combine;
    sim.model.combine = rule == "mean"       ? contact::CombineRule::Mean
                        : rule == "harmonic" ? contact::CombineRule::Harmonic
                                             : contact::CombineRule::Min;
  }
  sim.model.yadeMomentLimit = c.contact.momentLimit == "yade";
  sim.model.tanFriction = std::tan(degToRad(c.contact.frictionDeg));
  for (Wall& w : sim.box.walls) w.tanFriction = std::tan(degToRad(c.contact.wallFrictionDeg));
  if (c.test.platenFrictionDeg)
    for (int side = 0; side < 2; ++side) sim.box.walls[WallBox::index(2, side)].tanFriction = std::tan(degToRad(*c.test.platenFrictionDeg));
  // The sleeve's hoop stiffness; it pulls only once a test has set its unstretched radius.
  if (sim.boundary == Boundary::Membrane) sim.membrane.stiffness = c.test.membraneYoung * c.test.membraneThickness;
  sim.gravity = c.sample.gravity ? Vec3((*c.sample.gravity)[0], (*c.sample.gravity)[1], (*c.sample.gravity)[2]) : Vec3::Zero();
  sim.localDamping = c.solver.damping;
  sim.viscousDamping = c.solver.viscousDamping;
  sim.model.constantKn = c.contact.kn.value_or(0.0);
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

void holdIsotropicStress(Simulation& sim, double pressure) {
  holdIsotropicStress(*BoundaryControl::of(sim), pressure);
}

Laboratory::Laboratory(const RunConfig& config, ProgressFn progress)
    : config_(config), progress_(std::move(progress)) {
  sim_.boundary = config.test.boundary == "periodic"   ? Boundary::Periodic
                  : config.test.boundary == "membrane" ? Boundary::Membrane
                                                       : Boundary::Walls;
  boundary_ = BoundaryControl::of(sim_);
  // Ellipsoid samples get the shape columns too (a_tau, a_E, ... of lab/micromechanics.hpp).
  microColumns_.nonSpherical = config.sample.shape.type == "ellipsoid";
  static_assert(Record::kMicroColumns >= 11 + 2 + 6 * 3 + 2, "room for every micromechanical column");
}

Laboratory::Laboratory(const Laboratory& o)
    : config_(o.config_),
      progress_(o.progress_),
      snapshot_(o.snapshot_),
      snapshotEvery_(o.snapshotEvery_),
      checkpoint_(o.checkpoint_),
      checkpointEvery_(o.checkpointEvery_),
      shear_(o.shear_),
      sim_(o.sim_),
      records_(o.records_),
      window_(o.window_),
      previousWindow_(o.previousWindow_),
      micro_(o.micro_),
      microColumns_(o.microColumns_),
      d50_(o.d50_),
      growthCurve_(o.growthCurve_),
      deposition_(o.deposition_),
      layerDiameters_(o.layerDiameters_),
      underCompaction_(o.underCompaction_) {
  boundary_ = BoundaryControl::of(sim_);
  boundary_->restoreReference(o.boundary_->referenceLengths(), o.boundary_->referenceVolume());
  if (o.protocol_) {
    protocol_ = ShearProtocol::make(config_);
    protocol_->state = o.protocol_->state;
  }
}

EquilibriumState Laboratory::equilibriumState() const {
  return {boundaryStress(sim_), contactStress(sim_), unbalancedForceRatio(sim_), voidRatio(sim_),
          coordinationNumber(sim_)};
}

long Laboratory::consolidate(double pressure, const std::string& phase) {
  holdIsotropicStress(sim_, pressure);
  const long checkEvery = 100;
  const double stressTol = config_.solver.stressTolerance;
  const double unbTol = config_.solver.unbalancedTolerance;
  Pipeline pipeline(sim_);
  pipeline.addAfter("equilibrium check", [&] {
    const Vec3 s = boundaryStress(sim_);
    double dev = 0.0;
    if (sim_.boundary == Boundary::Walls && sim_.gravity.squaredNorm() > 0.0) {
      // Under gravity the pedestal carries the weight besides p: judge the faces that hold p.
      for (int k = 0; k < 6; ++k)
        if (sim_.box.walls[k].control == WallControl::Stress)
          dev = std::max(dev, std::abs(sim_.box.wallStress(k) - pressure) / pressure);
    } else {
      for (int a = 0; a < 3; ++a) dev = std::max(dev, std::abs(s[a] - pressure) / pressure);
    }
    if (sim_.boundary == Boundary::Periodic)  // a cell also servoes its shear stresses to zero
      for (int k = 0; k < 3; ++k) dev = std::max(dev, std::abs(sim_.cell.shearStress()[k]) / pressure);
    const double unb = unbalancedForceRatio(sim_);
    if (dev < stressTol && unb < unbTol) {
      pipeline.stop();
      return;
    }
    const long steps = pipeline.steps();
    // Progress: how far the worse of the two criteria is from its tolerance, on a log scale.
    const double worst = std::max(dev / stressTol, unb / unbTol);
    if (progress_ && steps % (10 * checkEvery) == 0)
      progress_(phase, std::clamp(1.0 - std::log10(std::max(worst, 1.0)) / 3.0, 0.0, 0.99), steps);
    if (steps >= config_.solver.maxSteps)
      throw SimulationError(fmt::format(
          "{}: no equilibrium after {} steps (stress off target by {:.3g} %, unbalanced force ratio "
          "{:.3g}); raise solver.max_steps or check the parameters", phase, steps, 100.0 * dev, unb));
  }, Pipeline::Trigger::period(checkEvery));
  const long steps = pipeline.run();
  if (progress_) progress_(phase, 1.0, steps);
  return steps;
}

long Laboratory::rampStiffness() {
  // A sudden stiffening would multiply every contact force by 1/factor at once and blow the packing
  // apart; a geometric ramp lets the boundary servos follow as the overlaps shrink.
  const double factor = config_.sample.prepStiffnessFactor;
  if (factor >= 1.0) return 0;
  const long rampSteps = config_.sample.prepRampSteps;
  const double growth = std::pow(1.0 / factor, 1.0 / static_cast<double>(rampSteps));
  const double dtFromYoung = sim_.dt * std::sqrt(sim_.model.young);  // dt scales as Ec^-1/2
  Pipeline pipeline(sim_);
  long i = 0;
  pipeline.addBefore("stiffness ramp", [&] {
    sim_.model.young = std::min(config_.contact.modelYoung(), sim_.model.young * growth);
    // Hertz–Mindlin's stiffness at a given load goes as E^(2/3), not E: the estimate again.
    sim_.dt = sim_.model.hertz() ? config_.solver.dtFactor * sim_.criticalTimeStep()
                                 : dtFromYoung / std::sqrt(sim_.model.young);
  });
  pipeline.addAfter("ramp progress", [&] {
    if (progress_ && i % 1000 == 0) progress_("stiffness ramp", static_cast<double>(i) / rampSteps, i);
    if (++i == rampSteps) pipeline.stop();
  });
  pipeline.run();
  return rampSteps;
}

long Laboratory::growRadii() {
  // Radius expansion ([O] §5.1, PFC's radius expansion): with the boundary held still and no
  // friction, every radius grows by the same factor each step until the mean contact stress reaches
  // the confining pressure. Positions, radii and the boundary are then scaled back by that factor,
  // so the radii are exactly the grading's again: with linear contacts whose Kn grows with the
  // radius the stress does not change under a uniform scaling (force ~ s^2, area ~ s^2).
  const double pressure = config_.test.confiningPressure;
  const double rate = config_.sample.growthRate;
  const double density = config_.sample.density;
  if (sim_.boundary == Boundary::Periodic) {
    for (int k = 0; k < 3; ++k) {
      sim_.cell.control[k] = CellControl::StrainRate;
      sim_.cell.strainRate[k] = 0.0;
    }
  } else {
    for (Wall& w : sim_.box.walls) {
      w.control = WallControl::Fixed;
      w.velocity = 0.0;
    }
  }
  const std::vector<double> radius0 = sim_.particles.radius;
  double scale = 1.0;
  Pipeline pipeline(sim_);
  pipeline.addBefore("radius growth", [&] {
    scale *= 1.0 + rate;
    for (std::size_t i = 0; i < radius0.size(); ++i) sim_.particles.setSphereRadius(i, scale * radius0[i], density);
  });
  pipeline.addAfter("growth target", [&] {
    const double p = contactStress(sim_).trace() / 3.0;
    if (progress_ && pipeline.steps() % 1000 == 0)
      progress_("radius growth", std::clamp(p / pressure, 0.0, 0.99), pipeline.steps());
    if (p >= pressure) pipeline.stop();
    if (pipeline.steps() >= config_.solver.maxSteps)
      throw SimulationError(fmt::format("radius growth: the pressure {:.3g} Pa was not reached in {} steps "
                                        "(reached {:.3g} Pa)", pressure, pipeline.steps(), p));
  });
  // The critical time step falls as the grains grow; take it for the final size up front.
  const double dt0 = sim_.dt;
  sim_.dt = dt0 / 1.5;
  const long steps = pipeline.run();
  const double inverse = 1.0 / scale;
  Particles& P = sim_.particles;
  for (std::size_t i = 0; i < P.size(); ++i) {
    P.setSphereRadius(i, radius0[i], density);
    P.position[i] *= inverse;
    P.velocity[i] *= inverse;
  }
  if (sim_.boundary == Boundary::Periodic) {
    sim_.cell.h *= inverse;
    sim_.cell.refresh();
  } else {
    for (Wall& w : sim_.box.walls) w.position *= inverse;
  }
  sim_.initialise(config_.solver.skinFraction);
  sim_.dt = dt0;
  return steps;
}

std::vector<double> assignRollingFriction(const RunConfig& c, Particles& particles) {
  const std::size_t n = particles.size();
  if (c.contact.rollingSlot() != "rolling-linear") return std::vector<double>(n, 1.0);
  if (!c.contact.sphericity) {
    particles.rollingFriction.assign(n, c.contact.rollingFriction);
    return std::vector<double>(n, 1.0);
  }
  const SphericityConfig& sc = *c.contact.sphericity;
  const SphericityDistribution& d = sc.distribution;
  if (d.values.empty() && d.frequency.empty())
    throw InputError(fmt::format("config error: contact.sphericity.file = {}: its distribution was not read with the config",
                                 io::quotedPath(sc.file)));
  // A stream of its own, so that giving grains a sphericity does not change the sample's grading.
  Rng rng(c.sample.seed ^ 0x9e3779b97f4a7c15ull);
  std::vector<double> psi = sampleSphericity(d, n, rng);
  particles.rollingFriction.resize(n);
  for (std::size_t i = 0; i < n; ++i) particles.rollingFriction[i] = rollingFrictionFromSphericity(psi[i], sc.c, sc.k);
  return psi;
}

GrainKinematics Laboratory::currentKinematics() const {
  // Before shearing the reference is the current state.
  if (!shear_.started) {
    GrainRecords reference = records_;
    reference.reset(sim_);
    return kinematicsSince(reference, sampleLengths(sim_));
  }
  return kinematicsSince(records_, shear_.l0);
}

GrainKinematics Laboratory::incrementKinematics() const {
  if (!shear_.started) return currentKinematics();
  return kinematicsSince(previousWindow_, shear_.previousWindowLengths);
}

GrainKinematics Laboratory::kinematicsSince(const GrainRecords& reference, const Vec3& l0) const {
  // The sample's homogeneous Green–Lagrange strain since the reference: from the lengths of the
  // box (a membrane sample's diameter and height), or from the cell, F = H H_ref^-1.
  Mat3 f = Mat3::Identity();
  if (sim_.boundary == Boundary::Periodic) {
    f = sim_.cell.h * reference.referenceCell.inverse();
  } else {
    const Vec3 l = sampleLengths(sim_);
    for (int a = 0; a < 3; ++a) f(a, a) = l[a] / l0[a];
  }
  Mat3 boxStrain = Mat3::Zero();
  if (sim_.boundary == Boundary::Periodic) {
    boxStrain = 0.5 * (f.transpose() * f - Mat3::Identity());
  } else {
    for (int a = 0; a < 3; ++a) boxStrain(a, a) = 0.5 * (f(a, a) * f(a, a) - 1.0);
  }
  // Grains with at least two contacts (walls included) carry load; the others are rattlers.
  const std::vector<int> contacts = contactsPerParticle(sim_);
  std::vector<char> active(contacts.size());
  for (std::size_t i = 0; i < contacts.size(); ++i) active[i] = contacts[i] >= 2;
  return grainKinematics(sim_, reference, boxStrain, kNeighbourhoodDiameters * d50_, config_.output.bandFactor,
                         active);
}

void Laboratory::closeBandWindow(Record& r, double strain) {
  ShearState& st = shear_;
  const std::optional<ShearBand> band = shearBand(kinematicsSince(window_, st.windowLengths));
  r.bandMeasured = 1.0;
  r.bandInclinationDeg = band ? band->inclinationDeg : std::nan("");
  r.bandThicknessD50 = band ? band->thickness / d50_ : std::nan("");
  st.bandFound = band.has_value();
  st.band = band.value_or(ShearBand{});
  ++st.bandWindows;
  previousWindow_ = std::move(window_);
  st.previousWindowLengths = st.windowLengths;
  window_.reset(sim_);  // the moved-from record; only positions, orientations and the cell are read
  st.windowStrain = strain;
  st.windowLengths = sampleLengths(sim_);
}

std::optional<ShearBand> Laboratory::shearBand(const GrainKinematics& k) const {
  if (sim_.boundary == Boundary::Periodic) return std::nullopt;
  ShearBandSettings settings;
  settings.binWidth = d50_;
  return findShearBand(sim_.particles.position, k.localShearStrain, k.inBand, k.active, settings);
}

std::size_t Laboratory::shearStateFieldCount() { return stateio::fieldCount<ShearState>(); }

void Laboratory::saveState(std::ostream& out) const {
  using namespace stateio;
  sim_.saveState(out);
  records_.saveState(out);
  window_.saveState(out);
  previousWindow_.saveState(out);
  put(out, d50_);
  put(out, shear_);
  put(out, protocol_ != nullptr);
  if (protocol_) {
    // Padding written as zeros (stateio::putFields), the layout the loader reads.
    using S = ProtocolState;
    putFields(out, protocol_->state, &S::direction, &S::path, &S::lastEps1, &S::halfCycles, &S::cycleEpsMin,
              &S::cycleEpsMax, &S::doubleAmplitude, &S::ruMax, &S::liquefiedCycles, &S::volumeDriftMax, &S::done,
              &S::cavitated, &S::drainageOpen, &S::cavitations, &S::cavitationStrain, &S::cavityMax, &S::waterRecovered,
              &S::recordDue, &S::lastRecorded, &S::segment, &S::segmentStart, &S::target, &S::stressDeviationMax,
              &S::pathFailed, &S::gamma0, &S::amplitude, &S::returning, &S::lastGamma, &S::lastTau, &S::cycleGammaMin,
              &S::cycleGammaMax, &S::cycleTauMin, &S::cycleTauMax, &S::loopArea, &S::secantModulus, &S::dampingRatio,
              &S::measuredAmplitude, &S::amplitudesDone);
  }
}

void Laboratory::loadState(std::istream& in) {
  using namespace stateio;
  sim_.loadState(in);
  records_.loadState(in);
  window_.loadState(in);
  previousWindow_.loadState(in);
  get(in, d50_);
  get(in, shear_);
  const ShearState& st = shear_;
  bool hasProtocol = false;
  get(in, hasProtocol);
  if (hasProtocol != st.started) throw std::runtime_error("inconsistent state: a shearing protocol's state without shearing, or none with it");
  if (hasProtocol) {
    protocol_ = ShearProtocol::make(config_);
    get(in, protocol_->state);
    const ProtocolState& ps = protocol_->state;
    if ((ps.direction != 1 && ps.direction != -1) || !(ps.path >= 0.0) || !std::isfinite(ps.path) || ps.halfCycles < 0 ||
        !std::isfinite(ps.lastEps1) || !std::isfinite(ps.ruMax) || !(ps.volumeDriftMax >= 0.0) ||
        !std::isfinite(ps.volumeDriftMax) || ps.cavitations < 0 || !std::isfinite(ps.cavitationStrain) ||
        ((ps.cavitated || ps.drainageOpen || ps.cavitations > 0) && !config_.test.cavitationPressure()) ||
        (ps.cavitations > 0) != (ps.cavitationStrain >= 0.0) || (ps.cavitated && ps.cavitations == 0) ||
        !(ps.cavityMax >= 0.0) || !std::isfinite(ps.cavityMax) || (ps.cavitations == 0 && !ps.waterRecovered))
      throw std::runtime_error("inconsistent state: the shearing protocol's state");
    boundary_->restoreReference(st.l0, st.v0);
  } else {
    protocol_.reset();
  }
  if (!(st.slowdown > 0.0 && st.slowdown <= 1.0)) throw std::runtime_error("inconsistent state: platen slow-down factor");
  if (!(st.pressureFactor >= kMinPressureRateFactor && st.pressureFactor <= 1.0) ||
      !(st.result.rateFactorMin >= kMinPressureRateFactor && st.result.rateFactorMin <= st.pressureFactor) ||
      (!config_.test.rateFollowsPressure && st.pressureFactor != 1.0))
    throw std::runtime_error("inconsistent state: loading-rate factor of test.rate_follows_pressure");
  if (st.loopNext < 0 || st.loopNext > static_cast<int>(config_.test.unloadReloadAt.size()) || st.loopPhase < 0 ||
      st.loopPhase > 3 || (st.loopPhase == 3 && !config_.test.loopRest) || (st.loopPhase != 0 && st.loopNext == static_cast<int>(config_.test.unloadReloadAt.size())))
    throw std::runtime_error("inconsistent state: unload-reload loop state does not match test.unload_reload_at");
  if (st.loopPhase == 3 && !(st.loopRestStart >= st.startStep && st.loopRestStart <= sim_.stepCount))
    throw std::runtime_error("inconsistent state: a loop's rest did not start during this test");
  // The engine's state was validated by sim_.loadState before anything was derived from it.
  if (records_.referencePosition.size() != sim_.particles.size() || records_.rotationPath.size() != sim_.particles.size() ||
      records_.referenceOrientation.size() != sim_.particles.size() || records_.sphericity.size() != sim_.particles.size())
    throw std::runtime_error("inconsistent state: grain records do not match the particles");
  for (const GrainRecords* w : {&window_, &previousWindow_})
    if (st.started && (w->referencePosition.size() != sim_.particles.size() ||
                       w->referenceOrientation.size() != sim_.particles.size()))
      throw std::runtime_error("inconsistent state: the shear band's window records do not match the particles");
  if (st.started && (st.bandWindows < 0 || !std::isfinite(st.windowStrain) ||
                     !(st.windowLengths.minCoeff() > 0.0 || sim_.boundary == Boundary::Periodic) ||
                     !(st.previousWindowLengths.minCoeff() > 0.0 || sim_.boundary == Boundary::Periodic)))
    throw std::runtime_error("inconsistent state: the shear band's strain windows");
  if (!(d50_ > 0.0) || !std::isfinite(d50_)) throw std::runtime_error("inconsistent state: d50 not positive");
}

}  // namespace grainlab::lab

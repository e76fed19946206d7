// The shearing tests (docs/laboratory.md §2), in a wall box or a periodic cell: drained triaxial
// compression (lateral stresses held at p, axial strain rate imposed), compression at constant mean
// stress ([O]: the lateral stresses follow (3p - sigma1)/2), true triaxial at constant p and b, and
// simple shear at constant normal stress (cell only).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "lab/macro.hpp"
#include "lab/measurements.hpp"
#include "lab/micro_network.hpp"
#include "lab/protocols.hpp"

namespace grainlab::lab {

Record Laboratory::measure(const Vec3* meanStress, double meanShearStress) const {
  Record r;
  r.step = sim_.stepCount;
  r.time = sim_.time;
  const Vec3 len = sampleLengths(sim_);
  const double h0 = shear_.started ? shear_.h0 : len[2];
  const double v0 = shear_.started ? shear_.v0 : sim_.volume();
  const Vec3 l0 = shear_.started ? shear_.l0 : len;
  r.eps1 = (h0 - len[2]) / h0;
  r.eps2 = (l0[0] - len[0]) / l0[0];
  r.eps3 = (l0[1] - len[1]) / l0[1];
  r.epsV = (v0 - sim_.volume()) / v0;
  const Vec3 s = meanStress ? *meanStress : boundaryStress(sim_);
  r.sigma1 = s[2];
  r.sigma2 = s[0];
  r.sigma3 = s[1];
  const double lateral = 0.5 * (r.sigma2 + r.sigma3);
  r.q = r.sigma1 - lateral;
  r.p = (r.sigma1 + r.sigma2 + r.sigma3) / 3.0;
  r.e = voidRatio(sim_);
  const TestConfig& t = config_.test;
  if (t.type == TestType::TrueTriaxial) {
    r.phiDeg = mobilisedFrictionDeg(r.sigma1, r.sigma3);
    r.b = std::abs(r.sigma1 - r.sigma3) > 1e-9 * r.p ? (r.sigma2 - r.sigma3) / (r.sigma1 - r.sigma3)
                                                      : std::numeric_limits<double>::quiet_NaN();
  } else {
    r.phiDeg = mobilisedFrictionDeg(r.sigma1, lateral);
  }
  r.coordination = coordinationNumber(sim_);
  r.unbalanced = unbalancedForceRatio(sim_);
  // The rate in force (test.rate_follows_pressure slows it; the factor is 1 otherwise).
  r.inertialNumber = shear_.result.strainRate * shear_.pressureFactor * d50_ *
                     std::sqrt(config_.sample.density / std::max(r.p, 1e-300));
  const Mat3 sc = contactStress(sim_);
  r.sigma1Contact = sc(2, 2);
  r.sigma2Contact = sc(0, 0);
  r.sigma3Contact = sc(1, 1);
  const Vec3 now = boundaryStress(sim_);
  r.sigma1Now = now[2];
  r.sigma2Now = now[0];
  r.sigma3Now = now[1];
  const Mat3 su = unbalancedStress(sim_);
  r.sigma1Unbalanced = su(2, 2);
  r.sigma2Unbalanced = su(0, 0);
  r.sigma3Unbalanced = su(1, 1);
  if (sim_.boundary == Boundary::Periodic) {
    r.eps1Log = -std::log(len[2] / h0);
    r.stressSkew = 0.5 * (sc - sc.transpose()).norm() / std::max(std::abs(sc.trace() / 3.0), 1e-300);
    r.gamma = sim_.cell.h(0, 2) / sim_.cell.h(2, 2) - (protocol_ ? protocol_->state.gamma0 : 0.0);
    r.tau = meanStress ? meanShearStress : -0.5 * (sc(0, 2) + sc(2, 0));
    if (info(t.type).strain == DrivingStrain::Shear) r.phiDeg = radToDeg(std::atan2(r.tau, r.sigma1));
  }
  const GrainKinematics k = currentKinematics();
  r.rotationMeanDeg = k.rotationMeanDeg;
  r.rotationBandMeanDeg = k.rotationBandMeanDeg;
  r.bandFraction = k.bandFraction;
  r.rotationOutsideMeanDeg = k.rotationOutsideMeanDeg;
  r.rotationBandStdDeg = k.rotationBandStdDeg;
  r.rotationOutsideStdDeg = k.rotationOutsideStdDeg;
  // The band is measured where a window closes (closeBandWindow), not at every record.
  r.bandInclinationDeg = std::nan("");
  r.bandThicknessD50 = std::nan("");
  r.kinetic = kineticEnergy(sim_);
  r.elastic = elasticEnergy(sim_);
  r.workBoundary = sim_.energy.boundaryWork;
  r.dissipSlip = sim_.energy.slip;
  r.dissipRoll = sim_.energy.rolling;
  r.dissipDamping = sim_.energy.damping;
  r.workGravity = sim_.energy.gravityWork;
  // External work: the boundary's, and gravity's (zero without gravity, so the sum is W_boundary).
  const double external = r.workBoundary + r.workGravity;
  if (shear_.started && external > 0.0) {
    const double stored = (r.elastic - shear_.elastic0) + (r.kinetic - shear_.kinetic0);
    r.energyResidual = (external - stored - r.dissipSlip - r.dissipRoll - r.dissipDamping) / external;
  } else {
    r.energyResidual = std::numeric_limits<double>::quiet_NaN();
  }
  const std::vector<std::optional<double>> micro = microRowValues(micro_.analyse(microNetwork(sim_)), microColumns_);
  r.micro.fill(std::numeric_limits<double>::quiet_NaN());
  for (std::size_t k = 0; k < micro.size() && k < r.micro.size(); ++k)
    if (micro[k]) r.micro[k] = *micro[k];
  if (protocol_) protocol_->completeRecord(r);
  return r;
}

double Laboratory::loadingFactor() const {
  const ShearState& st = shear_;
  // Both slow-downs act together: the unbalanced force's and the mean stress's (1 when off).
  const double slow = st.slowdown * st.pressureFactor;
  if (st.loopPhase == 3) return 0.0;
  if (st.loopPhase == 1) return -kLoopSpeedFactor * slow;
  if (st.loopPhase == 2) return kLoopSpeedFactor * slow;
  const double ramp = std::min(1.0, static_cast<double>(sim_.stepCount - st.startStep + 1) / st.rampSteps);
  if (st.loopEndStep < 0) return ramp * slow;
  // After a loop the platens speed up again from the loop's speed over the same ramp.
  return slow * std::min(ramp, kLoopSpeedFactor + (1.0 - kLoopSpeedFactor) *
                                                      static_cast<double>(sim_.stepCount - st.loopEndStep) /
                                                      st.rampSteps);
}

void Laboratory::beginShear() {
  ShearState& st = shear_;
  st = ShearState{};
  const TestConfig& t = config_.test;
  const double p = t.confiningPressure;
  const double rho = config_.sample.density;
  setFriction(config_.contact.frictionDeg);
  protocol_ = ShearProtocol::make(config_);
  // "auto": the fastest rate with inertial number I = rate d50 sqrt(rho/p) <= 1e-3, aimed at
  // kAutoInertialNumber (2 % below the limit) so that the servo's small dips of p stay under it.
  st.result.strainRate = protocol_->givenRate().value_or(protocol_->autoRateFactor() * kAutoInertialNumber /
                                                         (d50_ * std::sqrt(rho / p)));
  st.result.inertialNumber = st.result.strainRate * d50_ * std::sqrt(rho / p);

  BoundaryControl& b = boundary();
  b.beginTest();
  st.h0 = b.referenceLengths()[2];
  st.v0 = b.referenceVolume();
  st.l0 = b.referenceLengths();
  // A prepared cell is slightly skewed (its servo relaxed the shear stresses by shearing it: gamma
  // of a few 1e-3 to 2e-2); gamma is measured from here, as a laboratory measures shear strain.
  if (sim_.boundary == Boundary::Periodic) protocol_->state.gamma0 = sim_.cell.h(0, 2) / sim_.cell.h(2, 2);
  protocol_->configure(b);
  // Walls: platens at constant speed, the engineering axial strain rate on the initial height. Cell:
  // the same engineering rate of H_zz (or the shear rate). The rate is ramped up linearly over
  // kPlatenRampIntegralTimes servo integral times, so that the lateral servos learn how fast their
  // boundaries must move instead of lagging behind a sudden start (with the stiff contacts of [W]
  // sigma1 rises by several times p within 0.05 % of axial strain).
  st.rampSteps = std::max(1L, static_cast<long>(kPlatenRampIntegralTimes * config_.solver.servoIntegralSteps));
  st.started = true;
  records_.reset(sim_);
  // The first band window starts here.
  window_ = records_;
  previousWindow_ = records_;
  st.windowLengths = sampleLengths(sim_);
  st.previousWindowLengths = st.windowLengths;
  sim_.energy = EnergyLedger{};
  st.elastic0 = elasticEnergy(sim_);
  st.kinetic0 = kineticEnergy(sim_);

  st.result.records.push_back(measure());
  // Records are ten times denser below 1 % strain, where the moduli are measured.
  const double every = config_.output.recordEveryStrain;
  st.nextRecord = std::min(every, 0.1 * every);
  st.nextSnapshot = snapshotEvery_;
  st.nextCheckpoint = checkpointEvery_;
  st.startStep = sim_.stepCount;
  if (snapshot_) snapshot_(sim_, 0.0);
}

void Laboratory::buildShearPipeline(Pipeline& pipeline) {
  ShearState& st = shear_;
  const TestConfig& t = config_.test;
  const double p = t.confiningPressure;
  const double every = config_.output.recordEveryStrain;
  const std::string phase(protocol_->info().phase);
  ShearProtocol& protocol = *protocol_;
  BoundaryControl& b = boundary();
  // strain: the protocol's progress variable (records, snapshots and checkpoints are spaced in it);
  // axial: the strain it imposes (unload-reload loops).
  auto strain = std::make_shared<double>(0.0);
  auto axial = std::make_shared<double>(0.0);
  auto last = std::make_shared<bool>(false);

  pipeline.addBefore("loading drive", [this, &protocol, &b, &st] { protocol.drive(b, st.result.strainRate, loadingFactor()); });
  pipeline.addInside(
      "rotation record", "integrate",
      [this](std::size_t begin, std::size_t end) { records_.accumulateRotation(sim_.particles, sim_.dt, begin, end); },
      Simulation::kRotations, Simulation::kLaboratory);
  pipeline.addAfter("protocol", [&protocol, &b] { protocol.afterStep(b); });
  pipeline.addAfter("load cell", [this, &st, &protocol, &b, strain, axial, last] {
    const Mat3 sc = sim_.boundary == Boundary::Periodic ? sim_.cell.stress : Mat3::Zero();
    st.stressSum += boundaryStress(sim_);
    st.shearStressSum -= 0.5 * (sc(0, 2) + sc(2, 0));
    const auto walls = singleWallStresses(sim_);
    for (int k = 0; k < 6; ++k) st.wallStressSum[k] += walls[k];
    ++st.stressSamples;
    *axial = protocol.strain(b);
    *strain = protocol.progress(b);
    *last = protocol.finished(b);
  });
  if (t.platenSlowdownUnbalanced > 0.0)
    pipeline.addAfter("platen slow-down", [this, &st] {
      // A collapsing column shows as a burst of unbalanced force: the platens hold back while it
      // lasts, so that the lateral walls can follow the sudden contraction.
      const double threshold = config_.test.platenSlowdownUnbalanced;
      const double unbalanced = unbalancedForceRatio(sim_);
      st.slowdown = unbalanced > threshold ? std::max(kMinPlatenSlowdown, threshold / unbalanced) : 1.0;
    }, Pipeline::Trigger::onlyIf([this] { return sim_.stepCount % kSlowdownCheckSteps == 0; }));  // resumes in phase
  if (t.rateFollowsPressure)
    pipeline.addAfter("rate follows p'", [this, &st, p] {
      // The inertial number I = rate d50 sqrt(rho/p') held at its value at p0 while p' < p0.
      const Vec3 s = boundaryStress(sim_);
      const double pNow = std::max(0.0, (s[0] + s[1] + s[2]) / 3.0);
      st.pressureFactor = std::clamp(std::sqrt(pNow / (kPressureRateHeadroom * p)), kMinPressureRateFactor, 1.0);
      st.result.rateFactorMin = std::min(st.result.rateFactorMin, st.pressureFactor);
    }, Pipeline::Trigger::onlyIf([this] { return sim_.stepCount % kSlowdownCheckSteps == 0; }));  // resumes in phase
  if (!t.unloadReloadAt.empty())
    pipeline.addAfter("unload-reload", [this, &st, strain = axial] {
      // Reversal at the loop's strain, turning point at the stated fraction of the deviator at
      // reversal, end where the reload regains the reversal strain (the instantaneous wall stresses).
      const std::vector<double>& at = config_.test.unloadReloadAt;
      const Vec3 s = boundaryStress(sim_);
      const double q = s[2] - 0.5 * (s[0] + s[1]);
      const bool more = st.loopNext < static_cast<int>(at.size());
      if (st.loopPhase == 0 && more && *strain >= at[st.loopNext]) {
        st.loopPhase = config_.test.loopRest ? 3 : 1;
        st.loopQ = q;
        st.loopRestStart = sim_.stepCount;
        st.forceRecord = true;
      } else if (st.loopPhase == 3) {
        // At rest before the unload: the unload starts from the relaxed deviator.
        const long resting = sim_.stepCount - st.loopRestStart;
        if (resting % kSlowdownCheckSteps == 0 &&
            (resting >= kLoopMaxRestSteps || unbalancedForceRatio(sim_) < kProbeUnbalanced)) {
          st.loopPhase = 1;
          st.loopQ = q;
          st.forceRecord = true;
        }
      } else if (st.loopPhase == 1 && q <= config_.test.unloadToQFraction * st.loopQ) {
        st.loopPhase = 2;
        st.forceRecord = true;
      } else if (st.loopPhase == 2 && *strain >= at[st.loopNext]) {
        st.loopPhase = 0;
        ++st.loopNext;
        st.loopEndStep = sim_.stepCount;
        st.forceRecord = true;
      }
    });
  pipeline.addAfter("record", [this, &st, &protocol, strain, axial, last, every, p] {
    const bool loopDue = st.loopPhase != 0 && !st.result.records.empty() &&
                         (std::abs(*axial - st.result.records.back().eps1) >= kLoopRecordFraction * every ||
                          (st.loopPhase == 3 && sim_.stepCount - st.result.records.back().step >= kLoopRestRecordSteps));
    if (!(*strain >= st.nextRecord || *last || st.forceRecord || loopDue || protocol.recordDue())) return;
    st.forceRecord = false;
    const double samples = static_cast<double>(st.stressSamples);
    const Vec3 meanStress = st.stressSum / samples;
    Record r = measure(&meanStress, st.shearStressSum / samples);
    // How well the boundary held its lateral targets, as a fraction of p: the mean of the two
    // opposite walls (what the stresses report) and the worst single wall.
    if (const std::optional<Vec3> lateral = protocol.lateralTargets(r.sigma1)) {
      const Vec3& target = *lateral;
      st.result.maxLateralDeviation = std::max(
          {st.result.maxLateralDeviation, std::abs(r.sigma2 - target[0]) / p, std::abs(r.sigma3 - target[1]) / p});
      if (sim_.boundary == Boundary::Walls)
        for (int side = 0; side < 2; ++side)
          for (int a = 0; a < 2; ++a)
            st.result.maxSingleWallDeviation =
                std::max(st.result.maxSingleWallDeviation,
                         std::abs(st.wallStressSum[WallBox::index(a, side)] / samples - target[a]) / p);
    }
    st.stressSum.setZero();
    st.shearStressSum = 0.0;
    st.wallStressSum.fill(0.0);
    st.stressSamples = 0;
    r.loopPhase = st.loopPhase;
    // A band window closes at the first record past its length, and at the end of the test when
    // at least half a window has passed.
    const double window = config_.output.bandStrainWindow;
    const double windowDone = *strain - st.windowStrain;
    if (windowDone >= window * (1.0 - 1e-9) || (*last && windowDone >= 0.5 * window)) closeBandWindow(r, *strain);
    protocol.recorded(r);
    st.result.records.push_back(r);
    while (st.nextRecord <= *strain) st.nextRecord += *strain < 0.01 ? 0.1 * every : every;
  });
  pipeline.addAfter("snapshot", [this, &st, strain, last] {
    if (!(snapshot_ && snapshotEvery_ > 0.0 && (*strain >= st.nextSnapshot || *last))) return;
    snapshot_(sim_, *strain);
    while (st.nextSnapshot <= *strain) st.nextSnapshot += snapshotEvery_;
  });
  pipeline.addAfter("progress", [this, &st, &protocol, &b, phase] {
    if (progress_ && (sim_.stepCount - st.startStep) % 2000 == 0)
      progress_(phase, protocol.fractionDone(b), sim_.stepCount - st.startStep);
  });
  pipeline.addAfter("stop at the end of the test", [&pipeline, last] {
    if (*last) pipeline.stop();
  });
  // Checkpoints between steps, after the step's records and snapshots: a resumed run repeats none.
  pipeline.addAfter("checkpoint", [this, &st, &pipeline, strain] {
    if (pipeline.stopping() || !(checkpoint_ && checkpointEvery_ > 0.0 && *strain >= st.nextCheckpoint)) return;
    while (st.nextCheckpoint <= *strain) st.nextCheckpoint += checkpointEvery_;
    checkpoint_(*this);
  });
  pipeline.addAfter("step limit", [this, &st, &pipeline, strain, phase] {
    if (!pipeline.stopping() && sim_.stepCount - st.startStep >= config_.solver.maxSteps)
      throw SimulationError(fmt::format("{}: reached solver.max_steps = {} at strain {:.4f}", phase,
                                        config_.solver.maxSteps, *strain));
  });
}

std::vector<std::string> Laboratory::shearStageNames() {
  Pipeline pipeline(sim_);
  buildShearPipeline(pipeline);
  return pipeline.names();
}

ShearResult Laboratory::continueShear() {
  ShearState& st = shear_;
  // The test's servo cap (test.servo_max_speed), set here so that a resumed test has it too.
  sim_.servo.maxSpeed = config_.test.servoMaxSpeed;
  Pipeline pipeline(sim_);
  buildShearPipeline(pipeline);
  pipeline.run();
  if (progress_) progress_(std::string(protocol_->info().phase), 1.0, sim_.stepCount - st.startStep);
  st.result.steps = sim_.stepCount - st.startStep;
  return st.result;
}

ShearResult Laboratory::shear() {
  beginShear();
  return continueShear();
}

}  // namespace grainlab::lab

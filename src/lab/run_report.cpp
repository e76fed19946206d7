// The run report (lab/run_report.hpp): summary.json's keys from the laboratory's results.
#include "lab/run_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.hpp"
#include "lab/micro_network.hpp"
#include "lab/shear_band.hpp"
#include "lab/test_report.hpp"

namespace grainlab::lab {

namespace {

// test.boundary = "membrane": how the membrane was set up and where it ended.
Json membraneJson(const RunConfig& config, const Simulation& sim, double d50) {
  const Membrane& m = sim.membrane;
  Json j = Json::object();
  j["model"] = "pressure on the outermost grains of bins of the lateral surface (core/membrane.hpp)";
  j["bins_around"] = m.around;
  j["bins_along"] = m.along;
  j["bin_side_d50"] = config.test.membraneBinD50;
  j["shell_d50"] = m.shell / d50;
  j["aspect_ratio"] = config.test.aspectRatio;
  j["young_Pa"] = config.test.membraneYoung;
  j["thickness_m"] = config.test.membraneThickness;
  j["reference_diameter_m"] = 2.0 * m.referenceRadius;
  j["end_diameter_m"] = 2.0 * m.equivalentRadius();
  j["end_height_m"] = m.height;
  j["end_cell_pressure"] = m.pressure;
  j["end_radial_stress"] = m.radialStress();
  j["end_membrane_correction"] = m.hoopPressure;
  j["end_filled_bins_fraction"] = m.around * m.along > 0 ? static_cast<double>(m.filledBins) / (m.around * m.along) : 0.0;
  j["platen_friction_deg"] = config.test.platenFrictionDeg.value_or(config.contact.wallFrictionDeg);
  return j;
}

// JSON number that refuses NaN/inf (results never carry them silently).
double finite(double v, const char* name) {
  if (!std::isfinite(v)) throw SimulationError(fmt::format("non-finite result {}", name));
  return v;
}

Json optional(const std::optional<double>& v) { return v ? Json(*v) : Json(nullptr); }
// A value that is NaN where it could not be measured.
Json measured(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json gradingJson(const GradingStats& g) {
  return {{"d10", g.d10}, {"d30", g.d30}, {"d50", g.d50}, {"d60", g.d60},
          {"Cu", g.cu},   {"Cc", g.cc},   {"d_min", g.dMin}, {"d_max", g.dMax}};
}

Json equilibriumJson(const EquilibriumState& s) {
  return {{"wall_stress", {s.boundaryStress[0], s.boundaryStress[1], s.boundaryStress[2]}},
          {"coordination", s.coordination},
          {"contact_stress", {s.contactStress(0, 0), s.contactStress(1, 1), s.contactStress(2, 2)}},
          {"unbalanced", s.unbalanced},
          {"void_ratio", s.voidRatio}};
}

// q/p of three normal stresses (axial z first), NaN where p is not positive.
double stressRatio(double s1, double s2, double s3) {
  const double p = (s1 + s2 + s3) / 3.0;
  return p > 0.0 ? (s1 - 0.5 * (s2 + s3)) / p : std::numeric_limits<double>::quiet_NaN();
}

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The gap between the boundary's q/p (timeseries sigma1..3: means over the recording interval) and
// the contact stress's q/p (Love-Weber at the record's step), relative to the former, over the
// records with q/p > 0.05, and its two causes: the recording interval's mean against the step's
// value, and the grains' net contact forces (lab::unbalancedStress: wall stress = contact stress +
// that, exactly, at any step). `residual_max_abs` is what the two leave unexplained.
Json stressGapJson(const std::vector<Record>& records, std::size_t peak) {
  std::vector<double> gap, averaging, unbalanced;
  double residual = 0.0;
  auto rel = [](const Record& r) {
    const double b = r.q / r.p, c = stressRatio(r.sigma1Contact, r.sigma2Contact, r.sigma3Contact);
    return (c - b) / b;
  };
  for (const auto& r : records) {
    const double b = r.p > 0.0 ? r.q / r.p : 0.0;
    if (!(b > 0.05)) continue;
    const double now = stressRatio(r.sigma1Now, r.sigma2Now, r.sigma3Now);
    const double c = stressRatio(r.sigma1Contact, r.sigma2Contact, r.sigma3Contact);
    const double cu = stressRatio(r.sigma1Contact + r.sigma1Unbalanced, r.sigma2Contact + r.sigma2Unbalanced,
                                  r.sigma3Contact + r.sigma3Unbalanced);
    if (!std::isfinite(now) || !std::isfinite(c) || !std::isfinite(cu)) continue;
    gap.push_back((c - b) / b);
    averaging.push_back(std::abs(now - b) / b);
    unbalanced.push_back(std::abs(cu - c) / b);
    residual = std::max(residual, std::abs(cu - now) / b);
  }
  if (gap.empty()) return nullptr;
  double maxAbs = 0.0;
  for (double g : gap) maxAbs = std::max(maxAbs, std::abs(g));
  auto number = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
  return {{"definition",
           "(q/p of the Love-Weber contact stress at the record's step - q/p of the recorded boundary stress) / the "
           "latter, over the records with q/p > 0.05"},
          {"records", gap.size()},
          {"median", median(gap)},
          {"max_abs", maxAbs},
          {"at_peak", number(records[peak].p > 0.0 ? rel(records[peak]) : std::nan(""))},
          {"end", number(records.back().p > 0.0 ? rel(records.back()) : std::nan(""))},
          {"recording_mean_part_median_abs", median(averaging)},
          {"net_force_part_median_abs", median(unbalanced)},
          {"residual_max_abs", residual}};
}

// Fabric of the prepared sample: R = <n (x) n> over particle-particle contacts and its anisotropy
// a_r = 15/2 dev R (docs/micromechanics.md); a deposited sample prefers vertical contacts
// (a_r_zz > 0). Null without contacts.
Json fabricJson(const MicroAnalysis& micro) {
  Json fabric;
  fabric["R_diagonal"] = {micro.fabric(0, 0), micro.fabric(1, 1), micro.fabric(2, 2)};
  if (micro.ar) {
    const Mat3& a = micro.ar->tensor;
    fabric["a_r"] = std::sqrt(1.5 * a.cwiseProduct(a).sum());
    fabric["a_r_zz"] = a(2, 2);
    fabric["a_r_principal"] = {micro.ar->principal[0], micro.ar->principal[1], micro.ar->principal[2]};
  } else {
    fabric["a_r"] = nullptr;
    fabric["a_r_zz"] = nullptr;
    fabric["a_r_principal"] = nullptr;
  }
  return fabric;
}

// A warning for the console and the summary both.
void warnBoth(const std::string& w, ConsoleWarnings& console, Json& s) {
  console.push_back(w);
  s["warnings"].push_back(w);
}

Json underCompactionJson(const UnderCompactionReport& u, double d50, ConsoleWarnings& console, Json& s) {
  auto profile = [](const std::vector<double>& e) {
    Json out = Json::array();
    for (double v : e) out.push_back(std::isfinite(v) ? Json(v) : Json(nullptr));
    return out;
  };
  Json j = {{"layers", u.layers}, {"under_compaction", u.underCompaction},
            {"target_void_ratio", u.targetVoidRatio}, {"width", u.width},
            {"target_heights", u.targetHeights}, {"tamped_void_ratio", u.tampedVoidRatio},
            {"tamper_stress", u.tamperStress}, {"tamper_reached", u.tamperReached}, {"tamper_speed", u.tamperSpeed},
            {"void_ratio", u.voidRatio}, {"Z", u.coordination},
            {"a_r_zz", optional(u.fabricZz)},
            {"void_ratio_profile", profile(u.voidRatioProfile)},
            {"prepared_void_ratio_profile", profile(u.preparedProfile)},
            {"gravity_work", u.gravityWork}, {"steps", u.steps}};
  // A layer a few grains thick is mostly wall: its void ratio is the wall's, not the tamping's.
  const double layerThickness = u.targetHeights.empty() ? 0.0 : u.targetHeights.back() / u.layers;
  j["layer_thickness_d50"] = layerThickness / d50;
  if (layerThickness < 3.0 * d50)
    warnBoth(fmt::format("sample.layers = {}: each layer is {:.1f} d50 thick (under 3); more particles or fewer layers",
                         u.layers, layerThickness / d50),
             console, s);
  const long stalled = std::count(u.tamperReached.begin(), u.tamperReached.end(), false);
  if (stalled > 0)
    warnBoth(fmt::format("under-compaction: the tamper stalled at the confining pressure on {} of {} layers (they "
                         "stay looser than their target)",
                         stalled, u.layers),
             console, s);
  return j;
}

// The keys of an undrained test's volume constraint: volume_drift_max, with a warning above what
// the boundary should hold, and cavitation (test.back_pressure).
void volumeDriftKeys(const RunConfig& config, const ProtocolState& ps, Json& s) {
  const double drift = ps.volumeDriftMax;
  s["volume_drift_max"] = drift;
  const double allowed = config.test.boundary == "periodic" ? 1e-6 : 1e-5;
  if (drift > allowed)
    s["warnings"].push_back(
        fmt::format("the volume drifted by up to {:.3g} during the undrained test (> {:g})", drift, allowed));
  const std::optional<double> uCav = config.test.cavitationPressure();
  s["cavitation_pressure"] = optional(uCav);
  s["cavitated"] = uCav ? Json(ps.cavitations > 0) : Json(nullptr);
  s["cavitations"] = uCav ? Json(ps.cavitations) : Json(nullptr);
  s["cavitation_strain"] = ps.cavitations > 0 ? Json(ps.cavitationStrain) : Json(nullptr);
  if (uCav && ps.cavitations > 0)
    s["warnings"].push_back(fmt::format(
        "the pore water cavitated (u fell to {:.4g} kPa, test.back_pressure = {:g} Pa) at a strain of {:.4g}{}: "
        "while cavitated the test was drained at sigma' = p0 - u_cav, so volume_drift_max covers the undrained "
        "parts only",
        *uCav / 1e3, *config.test.backPressure, ps.cavitationStrain,
        ps.cavitations > 1 ? fmt::format(" ({} times)", ps.cavitations) : std::string()));
}

// The undrained keys (lab/test_report.hpp), with a warning where the volume was not held.
void undrainedKeys(const RunConfig& config, const std::vector<Record>& records, const ProtocolState& ps, Json& s) {
  const UndrainedSummary u =
      undrainedSummary(records, config.test.confiningPressure, config.test.ruLimit, ps.volumeDriftMax);
  s["u_max"] = finite(u.uMax, "u_max");
  s["p_min"] = finite(u.pMin, "p_min");
  s["q_at_phase_transformation"] = optional(u.qAtPhaseTransformation);
  s["eps1_at_phase_transformation"] = optional(u.eps1AtPhaseTransformation);
  s["liquefied"] = u.liquefied;
  s["u_min"] = finite(u.uMin, "u_min");
  volumeDriftKeys(config, ps, s);
}

// Eur of each unload–reload loop (lab/moduli.hpp); null when the test had no loop.
void moduliFromLoops(const RunConfig& config, const std::vector<UnloadReloadLoop>& loops, Json& s) {
  if (loops.empty()) {
    s["Eur_MPa"] = nullptr;
    s["Eur_method"] = "not measured (no test.unload_reload_at)";
    return;
  }
  Json eur = Json::array(), at = Json::array(), relaxed = Json::array(), measured = Json::array();
  bool rejected = false;
  for (const auto& l : loops) {
    // A reload secant that is not positive (the sample kept collapsing through the loop) is not an
    // unload-reload modulus: null, with the number in Eur_MPa_measured and a warning.
    const bool positive = l.eur && *l.eur > 0.0;
    measured.push_back(l.eur ? Json(finite(*l.eur / 1e6, "Eur_MPa")) : Json(nullptr));
    eur.push_back(positive ? measured.back() : Json(nullptr));
    if (l.eur && !positive) {
      rejected = true;
      s["warnings"].push_back(fmt::format(
          "Eur = {:.4g} MPa of the loop at eps1 = {:.4g} is not positive (the reload did not stiffen the sample); "
          "reported as null (Eur_MPa_measured keeps it)",
          *l.eur / 1e6, l.eps1Reversal));
    }
    at.push_back(l.eps1Reversal);
    relaxed.push_back(l.restRelaxation ? Json(finite(*l.restRelaxation, "Eur_rest_q_relaxation")) : Json(nullptr));
  }
  s["Eur_MPa"] = eur;
  if (rejected) s["Eur_MPa_measured"] = measured;
  s["Eur_at_eps1"] = at;
  // The fraction of q lost at constant strain during the rest before each unload (null: no rest).
  s["Eur_rest_q_relaxation"] = relaxed;
  s["Eur_method"] = fmt::format(
      "per loop: secant of the reload branch, from the turning point (unloaded to q = {} q at reversal) to where "
      "the reload regains the reversal strain; platens at {} of the loading speed{}",
      config.test.unloadToQFraction, Laboratory::kLoopSpeedFactor,
      config.test.loopRest ? fmt::format("; before each unload the platens stood still until the unbalanced-force "
                                         "ratio was below {} (q at reversal: after that rest)",
                                         Laboratory::kProbeUnbalanced)
                           : std::string());
}

double inertialMaxOf(const std::vector<Record>& records) {
  double inertialMax = 0.0;
  for (const auto& r : records) inertialMax = std::max(inertialMax, r.inertialNumber);
  return inertialMax;
}

// A monotonic test (triaxial, constant-p, true triaxial, simple shear): the curve's macro-values.
void reportMonotonic(const RunConfig& config, const ShearResult& shear, Laboratory& lab, Json& s, ShearReport& out) {
  const std::vector<Record>& records = shear.records;
  const bool simpleShear = config.test.type == TestType::SimpleShear;
  TriaxialCurves curves;
  // Unload–reload loops: the macro-parameters of the monotonic curve; the loops give Eur.
  std::vector<double> loopEps1, loopQ;
  std::vector<int> loopPhase;
  for (const auto& r : records) {
    loopEps1.push_back(r.eps1);
    loopQ.push_back(r.q);
    loopPhase.push_back(static_cast<int>(r.loopPhase));
    if (r.loopPhase != 0) continue;
    curves.eps1.push_back(simpleShear ? r.gamma : r.eps1);
    curves.epsV.push_back(r.epsV);
    curves.sigma1.push_back(r.sigma1);
    // True triaxial: the minor principal stress; otherwise the mean lateral stress.
    curves.sigma3.push_back(config.test.type == TestType::TrueTriaxial ? r.sigma3 : 0.5 * (r.sigma2 + r.sigma3));
    curves.voidRatio.push_back(r.e);
    curves.shearStress.push_back(r.tau);
  }
  MacroSettings criterion;
  criterion.csWindow = config.test.csWindow.value_or(
      autoCsWindow(simpleShear ? config.test.finalShearStrain : config.test.finalAxialStrain));
  const MacroParameters m = simpleShear ? computeSimpleShearMacro(curves, criterion) : computeMacro(curves, criterion);
  out.stressDilatancy = stressDilatancy(curves, simpleShear);
  out.simpleShear = simpleShear;
  s["phi_peak_deg"] = finite(m.phiPeakDeg, "phi_peak_deg");
  s["eps1_at_peak"] = m.eps1AtPeak;
  s["q_peak"] = m.qPeak;
  s["phi_res_deg"] = finite(m.phiResDeg, "phi_res_deg");
  s["residual_window_eps1"] = {m.residualFrom, records.back().eps1};
  s["psi_max_deg"] = m.psiMaxDeg ? Json(finite(*m.psiMaxDeg, "psi_max_deg")) : Json(nullptr);
  s["psi_max_tan_deg"] = m.psiMaxTanDeg ? Json(finite(*m.psiMaxTanDeg, "psi_max_tan_deg")) : Json(nullptr);
  s["eps1_at_psi_max"] = m.eps1AtPsiMax;
  if (simpleShear) {
    // Simple shear measures a shear modulus; Young's modulus and Poisson's ratio are not measured.
    s["G_MPa"] = finite(m.shearModulus / 1e6, "G_MPa");
    s["E50_MPa"] = nullptr;
    s["E50_method"] = "not measured (simple shear)";
    s["final_shear_strain"] = records.back().gamma;
    s["gamma0"] = lab.protocol()->state.gamma0;
  } else {
    s["E50_MPa"] = m.e50 ? Json(finite(*m.e50 / 1e6, "E50_MPa")) : Json(nullptr);
    s["E50_method"] = m.e50 ? "secant from the start of shearing to q = q_peak/2 (q_peak the largest deviator "
                              "of the monotonic curve), interpolated between records"
                            : "not measured (q never reached half its peak above its start)";
  }
  moduliFromLoops(config, unloadReloadLoops(loopEps1, loopQ, loopPhase), s);
  // The critical state only where the steady-state criterion (lab/macro.hpp) was met; the end of
  // the test always, with its rates, so that a sample still dilating says so.
  const SteadyState& cs = m.steady;
  s["residual_q_over_p"] = m.residualStressRatio;
  s["residual_void_ratio"] = m.residualVoidRatio;
  s["critical_state_reached"] = cs.reached;
  s["critical_state_eps1"] = cs.reached ? Json(cs.reachedAt) : Json(nullptr);
  s["cs_q_over_p"] = cs.reached ? Json(finite(cs.stressRatio, "cs_q_over_p")) : Json(nullptr);
  s["cs_void_ratio"] = cs.reached ? Json(finite(cs.voidRatio, "cs_void_ratio")) : Json(nullptr);
  s["cs_p"] = cs.reached ? Json(finite(cs.meanStress, "cs_p")) : Json(nullptr);
  s["end_q_over_p"] = cs.evaluated ? Json(finite(cs.endStressRatio, "end_q_over_p")) : Json(nullptr);
  s["end_void_ratio"] = cs.evaluated ? Json(finite(cs.endVoidRatio, "end_void_ratio")) : Json(nullptr);
  s["end_p"] = cs.evaluated ? Json(finite(cs.endMeanStress, "end_p")) : Json(nullptr);
  s["end_rates"] = cs.evaluated ? Json{{"d_q_over_p", cs.endStressRatioRate},
                                       {"d_eps_v", cs.endVolumetricRate},
                                       {"d_e", cs.endVoidRatioRate}}
                                : Json(nullptr);
  s["critical_state_window"] = criterion.csWindow;
  s["critical_state_criterion"] = fmt::format(
      "every trailing window of {} {} from critical_state_eps1 to the end has |d(q/p)/d eps| <= {}, |d eps_v/d eps| "
      "<= {} and |d e/d eps| <= {} (least-squares slopes, >= {} records); cs_* are the means from "
      "critical_state_eps1 to the end, end_* those of the last window",
      criterion.csWindow, simpleShear ? "shear strain" : "axial strain", criterion.csMaxStressRatioRate,
      criterion.csMaxVolumetricRate, criterion.csMaxVoidRatioRate, criterion.csMinRecords);
  if (lab.protocol()->undrained()) undrainedKeys(config, records, lab.protocol()->state, s);
  s["strain_rate"] = shear.strainRate;
  s["inertial_number"] = shear.inertialNumber;
  if (config.test.rateFollowsPressure) s["rate_factor_min"] = shear.rateFactorMin;
  // Simple shear has no lateral stress target: not measured.
  s["lateral_stress_max_deviation"] = simpleShear ? Json(nullptr) : Json(shear.maxLateralDeviation);
  if (config.test.boundary == "walls") s["lateral_stress_max_deviation_single_wall"] = shear.maxSingleWallDeviation;
  if (config.test.boundary == "membrane") s["membrane"] = membraneJson(config, lab.simulation(), lab.d50());
  s["shear_pipeline"] = lab.shearStageNames();
  if (shear.maxLateralDeviation > 0.02)
    out.warnings.push_back(
        fmt::format("lateral stress deviated from sigma3 by up to {:.1f} % (> 2 %)", 100.0 * shear.maxLateralDeviation));
  s["final_axial_strain"] = records.back().eps1;
  s["shear_steps"] = shear.steps;
  // Micromechanics at the peak (the record nearest the peak's strain) and at the end; the largest
  // energy balance residual over the test (null when no record measured one).
  std::size_t peak = 0;
  for (std::size_t i = 0; i < records.size(); ++i)
    if (std::abs(curves.eps1[i] - m.eps1AtPeak) < std::abs(curves.eps1[peak] - m.eps1AtPeak)) peak = i;
  const std::vector<std::string> names = lab.microColumnNames();
  s["micro_at_peak"] = microJson(records[peak], names);
  if (!simpleShear) s["boundary_contact_gap"] = stressGapJson(records, peak);
  s["micro_at_end"] = microJson(records.back(), names);
  std::optional<double> residualMax;
  for (const auto& r : records)
    if (std::isfinite(r.energyResidual)) residualMax = std::max(residualMax.value_or(0.0), std::abs(r.energyResidual));
  s["energy_residual_max"] = optional(residualMax);
  // Grain rotations at the end of the test, inside and outside the shear band (kinematics.hpp).
  const GrainKinematics k = lab.currentKinematics();
  // Null where not measured (no grain in the band, or no homogeneous strain to compare with).
  s["rotation_mean_deg"] = measured(k.rotationMeanDeg);
  s["rotation_band_mean_deg"] = measured(k.rotationBandMeanDeg);
  s["rotation_outside_band_mean_deg"] = measured(k.rotationOutsideMeanDeg);
  s["band_fraction"] = measured(k.bandFraction);
  s["rotation_band_std_deg"] = measured(k.rotationBandStdDeg);
  s["rotation_outside_band_std_deg"] = measured(k.rotationOutsideStdDeg);
  const bool bandMeasured = lab.bandWindows() > 0 && lab.simulation().boundary != Boundary::Periodic;
  s["shear_band"] = shearBandJson(lab.lastShearBand(), bandMeasured, lab.simulation(), lab.d50(), bandOnset(records),
                                  m.eps1AtPeak);
  s["shear_band_method"] = fmt::format(
      "from the strain increment over windows of output.band_strain_window = {:g} of the driving strain, one "
      "closing at the first record past its length (timeseries band_measured = 1 there; the last at the end of "
      "the test when half a window has passed): the load-bearing grains whose local eq over the window is >= "
      "output.band_factor times the sample's; a band when they are >= 20 and <= half the load-bearing grains and "
      "lie in a slab (smallest/middle eigenvalue of their position covariance <= 0.25); its plane fitted to the "
      "centroids of full columns of them along the normal, inclination_deg = the plane's angle to the horizontal, "
      "thickness_d50 = full width at half height of the mean eq profile across it (bins of d50) above the "
      "background (the median eq outside); void_ratio_inside/outside: the box's volume (a membrane sample's: inside the membrane) and the grains' solid (by "
      "spherical caps, exact for spheres) within and beyond the slab of that thickness at the end; shear_band is "
      "the last window's band (detected false: none found there; null: no window closed, or a periodic cell, "
      "where a band may wrap across the faces); onset_eps1 = the end of the first window from which every window "
      "to the end has a band, onset_over_peak = that over eps1_at_peak",
      config.output.bandStrainWindow);
  // I = rate d50 sqrt(rho/p) with the p measured at each record.
  const double inertialMax = inertialMaxOf(records);
  s["inertial_number_max"] = inertialMax;
  s["quasi_static"] = inertialMax <= 1e-3;
  if (inertialMax > 1e-3)
    out.warnings.push_back(
        fmt::format("inertial number reached {:.2e} > 1e-3: the test was not quasi-static", inertialMax));
}

// Oedometer, cyclic tests and stress paths: their own macro-values (lab/test_report.hpp), not a
// monotonic curve's peak and residual.
void reportReversing(const RunConfig& config, const ShearResult& shear, Laboratory& lab, Json& s) {
  const std::vector<Record>& records = shear.records;
  const ShearProtocol& protocol = *lab.protocol();
  if (config.test.type == TestType::Oedometer) {
    const OedometerSummary o = oedometerSummary(records, config.test.confiningPressure);
    s["K0"] = optional(o.k0);
    s["K0_unloading"] = optional(o.k0Unloading);
    s["Cc"] = optional(o.cc);
    s["Cs"] = optional(o.cs);
    s["sigma_v_max"] = o.sigmaVMax;
    s["oedometer_method"] = fmt::format(
        "lateral strain zero; K0 = sigma_h/sigma_v averaged over the {} loading records with sigma_v >= sqrt(p0 "
        "sigma_v_max) (the start is isotropic), K0_unloading at the last record; Cc, Cs = -de/dlog10(sigma_v), "
        "least-squares over the same loading records and over the {} unloading records",
        o.loadingRecords, o.unloadingRecords);
  } else if (config.test.type == TestType::CyclicSimpleShear) {
    const ProtocolState& ps = protocol.state;
    const std::size_t n = static_cast<std::size_t>(ps.amplitudesDone);
    Json amplitudes = Json::array(), g = Json::array(), ratio = Json::array(), damping = Json::array();
    // Gmax: the secant modulus at the smallest amplitude.
    const double gmax = n > 0 ? ps.secantModulus[0] : 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      amplitudes.push_back(ps.measuredAmplitude[i]);
      g.push_back(ps.secantModulus[i] / 1e6);
      ratio.push_back(gmax > 0.0 ? Json(ps.secantModulus[i] / gmax) : Json(nullptr));
      damping.push_back(ps.dampingRatio[i]);
    }
    s["shear_strain_amplitudes"] = amplitudes;
    s["G_secant_MPa"] = g;
    s["G_over_Gmax"] = ratio;
    s["damping_ratio"] = damping;
    s["Gmax_MPa"] = n > 0 ? Json(gmax / 1e6) : Json(nullptr);
    s["gamma0"] = ps.gamma0;
    s["cycles_per_amplitude"] = config.test.cyclesPerAmplitude;
    s["G_method"] = fmt::format(
        "per amplitude, over its last of {} cycles: G = (tau_max - tau_min)/(gamma_max - gamma_min) (secant), "
        "damping ratio = W_D/(4 pi W_S), W_D the loop area (integral of tau dgamma every step), W_S = G "
        "gamma_a^2/2 with gamma_a the half-range of gamma; shear_strain_amplitudes are the measured half-ranges; "
        "Gmax = G at the smallest amplitude",
        config.test.cyclesPerAmplitude);
    if (n > 0 && config.test.shearStrainAmplitudes[0] > 1e-5)
      s["warnings"].push_back(fmt::format(
          "the smallest amplitude {} is above 1e-5: Gmax (G at that amplitude) may be below the elastic "
          "small-strain modulus",
          config.test.shearStrainAmplitudes[0]));
    s["ru_max"] = protocol.undrained() ? Json(ps.ruMax) : Json(nullptr);
    if (protocol.undrained()) {
      // Per amplitude, the largest ru = u/p0 recorded while it was cycled (records carry the
      // amplitude's index + 1); liquefied: ru reached test.ru_limit at some step (ps.ruMax).
      Json ruPer = Json::array();
      std::optional<double> liquefiedAt;
      const double p0 = config.test.confiningPressure;
      for (std::size_t i = 0; i < n; ++i) {
        double m = -std::numeric_limits<double>::infinity();
        for (const Record& r : records)
          if (r.pathSegment == static_cast<long>(i) + 1) m = std::max(m, r.u / p0);
        ruPer.push_back(std::isfinite(m) ? Json(m) : Json(nullptr));
        if (!liquefiedAt && std::isfinite(m) && m >= config.test.ruLimit) liquefiedAt = ps.measuredAmplitude[i];
      }
      const bool liquefied = ps.ruMax >= config.test.ruLimit;
      s["ru_max_per_amplitude"] = ruPer;
      s["liquefied"] = liquefied;
      s["liquefied_at_amplitude"] = optional(liquefiedAt);
      if (liquefied)
        s["warnings"].push_back(fmt::format(
            "the sample liquefied (ru = u/p0 reached {:.4g} >= test.ru_limit = {}){}: G/Gmax and the damping ratio "
            "from there on are those of a liquefied sample (sigma_zz near zero), not of the soil's modulus curve",
            ps.ruMax, config.test.ruLimit,
            liquefiedAt ? fmt::format(" in the cycles at gamma_a = {:.3g}", *liquefiedAt) : std::string()));
      volumeDriftKeys(config, ps, s);
    }
  } else if (config.test.type == TestType::StressPath) {
    const ProtocolState& ps = protocol.state;
    const double sEnd = config.test.path.back().s;
    s["path_points"] = config.test.path.size();
    s["path_source"] = config.test.pathSource.empty() ? Json(nullptr) : Json(config.test.pathSource);
    s["path_completed"] = !ps.pathFailed;
    s["path_s_reached"] = ps.path;
    s["path_stress_deviation_max"] = ps.stressDeviationMax;
    s["path_method"] =
        "s advances at test.axial_strain_rate; per segment each axis moves linearly in s from where the segment "
        "began to the point's target; path_stress_deviation_max = max |sigma - target| / test.confining_pressure "
        "of a stress-controlled axis over every step (the servo's lag)";
    if (ps.pathFailed)
      s["warnings"].push_back(fmt::format(
          "the stress path stopped at s = {:.6g} of {:.6g}: a strain reached test.final_axial_strain = {} (a stress "
          "target beyond what the sample carries)",
          ps.path, sEnd, config.test.finalAxialStrain));
  } else {
    const CyclicSummary c = cyclicSummary(protocol.state);
    s["n_cycles_to_liquefaction"] = optional(c.cyclesToLiquefaction);
    s["ru_max"] = protocol.undrained() ? Json(c.ruMax) : Json(nullptr);
    s["cycles"] = c.cycles;
    s["double_amplitude_strain_max"] = c.doubleAmplitudeMax;
    s["csr"] = config.test.csr;
    s["liquefaction_criterion"] = fmt::format(
        "{}double-amplitude axial strain of a cycle >= {}; n_cycles_to_liquefaction counts the half cycle it "
        "happened in (0.5: the first compression)",
        protocol.undrained() ? fmt::format("ru = 1 - p'/p0 >= {} or ", config.test.ruLimit) : std::string(),
        config.test.liquefactionDaStrain);
    if (protocol.undrained()) volumeDriftKeys(config, protocol.state, s);
  }
  s["strain_rate"] = shear.strainRate;
  s["inertial_number"] = shear.inertialNumber;
  if (config.test.rateFollowsPressure) s["rate_factor_min"] = shear.rateFactorMin;
  s["shear_pipeline"] = lab.shearStageNames();
  s["final_axial_strain"] = records.back().eps1;
  s["shear_steps"] = shear.steps;
  s["micro_at_end"] = microJson(records.back(), lab.microColumnNames());
  const double inertialMax = inertialMaxOf(records);
  s["inertial_number_max"] = inertialMax;
  s["quasi_static"] = inertialMax <= 1e-3;
}

}  // namespace

ConsoleWarnings reportPreparation(const RunConfig& config, const PreparationResult& prep, const Laboratory& lab,
                                  bool fromPacking, Json& s) {
  ConsoleWarnings console;
  const Simulation& sim = lab.simulation();
  s["n_particles"] = sim.particles.size();
  s["e0"] = finite(prep.e0, "e0");
  // With a given prep_friction_deg there is no search and e0 is simply what that friction gives.
  // Only compaction searches (growth, lattice, deposition and under-compaction reach their own e0).
  const bool searching = config.sample.method == "compaction" || config.sample.method == "loose-moment-free";
  s["e0_searched"] = config.sample.packing.empty() && !config.sample.prepFrictionDeg.has_value() && searching;
  s["e0_within_tolerance"] = std::abs(prep.e0 - config.sample.e0) <= config.sample.e0Tolerance;
  if (!s["e0_within_tolerance"].get<bool>() && !fromPacking &&
      (searching || config.sample.method == "under-compaction")) {
    // A missed e0 target (a given prep_friction_deg is not searched) is reported, never silent.
    warnBoth(fmt::format(
                 "e0 = {:.4f} misses sample.e0 = {} by more than sample.e0_tolerance = {}{}", prep.e0, config.sample.e0,
                 config.sample.e0Tolerance,
                 config.sample.method == "under-compaction"
                     ? std::string(" (under-compaction tamps the layers to e0; consolidation to p then compresses them)")
                 : config.sample.prepFrictionDeg
                     ? fmt::format(" (sample.prep_friction_deg = {} is fixed, not searched)", *config.sample.prepFrictionDeg)
                     : std::string()),
             console, s);
  }
  // A packing file is taken as it is: no preparation friction was used.
  s["prep_friction_deg"] = optional(prep.prepFrictionDeg);
  if (fromPacking) s["packing_friction_deg"] = optional(config.sample.packingFrictionDeg);
  s["preparation_method"] = config.sample.packing.empty() ? config.sample.method : "packing file";
  Json search = Json::array();
  for (const auto& [mu, e] : prep.search) search.push_back({{"prep_friction_deg", mu}, {"e", e}});
  s["prep_search"] = search;
  s["grading"] = gradingJson(prep.grading);
  if (config.contact.rollingSlot() == "rolling-linear") {
    const auto& mu = sim.particles.rollingFriction;
    double sum = 0.0;
    for (double m : mu) sum += m;
    s["mu_r_mean"] = sum / static_cast<double>(mu.size());
    s["mu_r_min"] = *std::min_element(mu.begin(), mu.end());
    s["mu_r_max"] = *std::max_element(mu.begin(), mu.end());
  }
  s["isotropic_state"] = equilibriumJson(prep.state);
  // Coordination after preparation; a sample standing at Z < 2 is a house of cards (tenuous arches
  // held by contact moments) that collapses at the first load.
  s["Z"] = prep.coordination.Z;
  s["Z_mech"] = optional(prep.coordination.Zmech);
  s["rattler_fraction"] = prep.coordination.rattlerFraction;
  s["house_of_cards"] = prep.coordination.Z < 2.0;
  if (prep.coordination.Z < 2.0)
    console.push_back(fmt::format("the prepared sample stands at Z = {:.2f} < 2 (a house of cards)", prep.coordination.Z));
  s["fabric_after_preparation"] = fabricJson(lab.microAnalyzer().analyse(microNetwork(sim)));
  if (prep.deposition) {
    const DepositionReport& d = *prep.deposition;
    s["deposition"] = {{"drop_height", d.dropHeight}, {"cloud_height", d.cloudHeight},
                       {"cloud_solid_fraction", d.cloudSolidFraction}, {"width", d.width},
                       {"bed_height", d.bedHeight}, {"settled_void_ratio", d.settledVoidRatio},
                       {"settled_Z", d.settledCoordination}, {"settled_a_r_zz", optional(d.settledFabricZz)},
                       {"gravity_work", d.gravityWork}, {"steps", d.steps}};
  }
  if (prep.underCompaction) s["under_compaction"] = underCompactionJson(*prep.underCompaction, prep.grading.d50, console, s);
  s["dt"] = sim.dt;
  s["dt_critical"] = sim.criticalTimeStep();
  s["preparation_steps"] = prep.steps;
  if (!prep.growth.empty()) {
    // [O]'s growth curve: Z (and its spread over the particles) and packing fraction per stage.
    Json curve = Json::array();
    for (const auto& g : prep.growth)
      curve.push_back({{"eccentricity", g.eccentricity}, {"Z", g.coordination}, {"Z_std", g.coordinationStd},
                       {"packing_fraction", g.packingFraction}});
    s["growth_curve"] = curve;
  }
  return console;
}

// A probe whose nu0 leaves [0, 0.5] or whose E0 is not positive did not measure an isotropic elastic
// response (the probe strain reached slip or collapse): the value is null, the number the probe
// gave stays in nu0_measured / E0_MPa_measured, and a warning says so.
void reportProbe(const ModulusProbe& probe, Json& s) {
  const bool ok = probe.elastic.has_value();
  s["E0_MPa"] = ok ? Json(finite(probe.elastic->young / 1e6, "E0_MPa")) : Json(nullptr);
  s["nu0"] = ok ? Json(finite(probe.elastic->poisson, "nu0")) : Json(nullptr);
  if (ok && (probe.elastic->poisson < 0.0 || probe.elastic->poisson > 0.5)) {
    s["nu0_measured"] = s["nu0"];
    s["nu0"] = nullptr;
    s["warnings"].push_back(fmt::format("nu0 = {:.3f} from the probe is outside [0, 0.5], not an elastic Poisson ratio; "
                                        "reported as null (nu0_measured keeps it)",
                                        probe.elastic->poisson));
  }
  if (ok && probe.elastic->young <= 0.0) {
    s["E0_MPa_measured"] = s["E0_MPa"];
    s["E0_MPa"] = nullptr;
    s["warnings"].push_back(fmt::format("E0 = {:.4g} MPa from the probe is not positive; reported as null "
                                        "(E0_MPa_measured keeps it)",
                                        probe.elastic->young / 1e6));
  }
  s["E0_method"] = probe.method;
  s["E0_probe"] = {{"strain", probe.strain}, {"d_sigma1", probe.dSigma1}, {"d_sigma3", probe.dSigma3},
                   {"d_eps1", probe.dEps1}, {"d_eps3", probe.dEps3}, {"steps", probe.steps},
                   {"settled", probe.settled}};
  s["E_MPa"] = s["E0_MPa"];
  s["nu"] = s["nu0"];
}

ShearReport reportShear(const RunConfig& config, const ShearResult& shear, Laboratory& lab, Json& summary) {
  ShearReport out;
  if (info(config.test.type).monotonic)
    reportMonotonic(config, shear, lab, summary, out);
  else
    reportReversing(config, shear, lab, summary);
  return out;
}

Json shearBandJson(const std::optional<ShearBand>& b, bool measured, const Simulation& sim, double d50,
                   std::optional<double> onset, double eps1AtPeak) {
  if (!b) {
    Json none = Json::object();
    none["detected"] = measured ? Json(false) : Json(nullptr);
    for (const char* key : {"inclination_deg", "thickness_d50", "onset_eps1", "onset_over_peak", "void_ratio_inside",
                            "void_ratio_outside", "normal", "centre", "grains", "flatness", "peak_local_strain",
                            "background_local_strain"})
      none[key] = nullptr;
    return none;
  }
  // A membrane sample: the cylinder inside the membrane, not the box around it.
  const bool membrane = sim.boundary == Boundary::Membrane;
  const Membrane& m = sim.membrane;
  const double reach = membrane && !m.binRho.empty() ? *std::max_element(m.binRho.begin(), m.binRho.end()) : 0.0;
  const Vec3 lo = membrane ? Vec3(m.axisX - reach, m.axisY - reach, m.bottom) : sim.box.lowerCorner();
  const Vec3 hi = membrane ? Vec3(m.axisX + reach, m.axisY + reach, m.bottom + m.height) : sim.box.upperCorner();
  const std::optional<BandVoidRatios> e =
      bandVoidRatios(*b, sim.particles.position, sim.particles.semiAxes, lo, hi,
                     membrane ? std::function<bool(const Vec3&)>([&m](const Vec3& x) { return m.contains(x); })
                              : std::function<bool(const Vec3&)>());
  return {{"detected", true},
          {"inclination_deg", finite(b->inclinationDeg, "shear_band.inclination_deg")},
          {"onset_eps1", optional(onset)},
          {"onset_over_peak", onset && eps1AtPeak > 0.0 ? Json(finite(*onset / eps1AtPeak, "shear_band.onset_over_peak"))
                                                       : Json(nullptr)},
          {"void_ratio_inside", e ? Json(finite(e->inside, "shear_band.void_ratio_inside")) : Json(nullptr)},
          {"void_ratio_outside", e ? Json(finite(e->outside, "shear_band.void_ratio_outside")) : Json(nullptr)},
          {"thickness_d50", finite(b->thickness / d50, "shear_band.thickness_d50")},
          {"normal", {b->normal.x(), b->normal.y(), b->normal.z()}},
          {"centre", {b->centre.x(), b->centre.y(), b->centre.z()}},
          {"grains", b->grains},
          {"flatness", b->flatness},
          {"peak_local_strain", b->peakStrain},
          {"background_local_strain", b->backgroundStrain}};
}

std::optional<double> bandOnset(const std::vector<Record>& records) {
  std::optional<double> onset;
  for (auto r = records.rbegin(); r != records.rend(); ++r) {
    if (r->bandMeasured == 0.0) continue;
    if (!std::isfinite(r->bandInclinationDeg)) break;
    onset = r->eps1;
  }
  return onset;
}

Json microJson(const Record& r, const std::vector<std::string>& names) {
  Json out = Json::object();
  for (std::size_t k = 0; k < names.size(); ++k)
    out[names[k]] = std::isfinite(r.micro.at(k)) ? Json(r.micro[k]) : Json(nullptr);
  out["energy_residual"] = std::isfinite(r.energyResidual) ? Json(r.energyResidual) : Json(nullptr);
  out["eps1"] = r.eps1;
  return out;
}

}  // namespace grainlab::lab

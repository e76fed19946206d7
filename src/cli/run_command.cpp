#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/progress.hpp"
#include "core/errors.hpp"
#include "io/config.hpp"
#include "io/packing.hpp"
#include "io/vtk.hpp"
#include "io/results.hpp"
#include "lab/macro.hpp"
#include "lab/protocols.hpp"

namespace grainlab::cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// JSON number that refuses NaN/inf (results never carry them silently).
double finite(double v, const char* name) {
  if (!std::isfinite(v)) throw SimulationError(fmt::format("non-finite result {}", name));
  return v;
}

json gradingJson(const lab::GradingStats& g) {
  return {{"d10", g.d10}, {"d30", g.d30}, {"d50", g.d50}, {"d60", g.d60},
          {"Cu", g.cu},   {"Cc", g.cc},   {"d_min", g.dMin}, {"d_max", g.dMax}};
}

json equilibriumJson(const lab::EquilibriumState& s) {
  return {{"wall_stress", {s.wallStress[0], s.wallStress[1], s.wallStress[2]}},
          {"contact_stress", {s.contactStress(0, 0), s.contactStress(1, 1), s.contactStress(2, 2)}},
          {"unbalanced", s.unbalanced},
          {"void_ratio", s.voidRatio}};
}

void makePlots(const fs::path& dir, bool quiet) {
  const fs::path script = fs::path(GRAINLAB_SOURCE_DIR) / "tools" / "plot_run.py";
  if (!fs::exists(script)) return;
  const std::string cmd = fmt::format("\"{}\" \"{}\" \"{}\"{}", GRAINLAB_PYTHON, script.string(),
                                      dir.string(), quiet ? " >/dev/null 2>&1" : "");
  if (std::system(cmd.c_str()) != 0)
    std::fprintf(stderr, "grainlab: warning: plotting failed (results are complete without plots)\n");
}

lab::RunConfig resolveConfig(const RunOptions& opt) {
  toml::table table = io::loadConfigTable(opt.config);
  for (const auto& s : opt.overrides) io::applyOverride(table, s);
  if (!opt.outDir.empty()) io::applyOverride(table, "output.dir=\"" + opt.outDir + "\"");
  if (opt.threads > 0) io::applyOverride(table, fmt::format("solver.threads={}", opt.threads));
  return io::parseConfig(table, io::configBaseDir(opt.config));
}

}  // namespace

int checkConfig(const RunOptions& opt) {
  std::fputs(io::toTomlString(io::resolvedTable(resolveConfig(opt))).c_str(), stdout);
  return 0;
}

int runLab(const RunOptions& opt) {
  const lab::RunConfig config = resolveConfig(opt);
  omp_set_num_threads(config.solver.threads);

  const fs::path dir = config.output.dir;
  fs::create_directories(dir);
  io::writeFileAtomic(dir / "config.resolved.toml", io::toTomlString(io::resolvedTable(config)));

  ProgressLine progress(opt.quiet);
  const auto t0 = std::chrono::steady_clock::now();
  json summary;
  summary["config_source"] = opt.config;
  summary["n_particles"] = config.sample.nParticles;
  summary["confining_pressure"] = config.test.confiningPressure;
  summary["test"] = config.test.type;
  summary["e0_target"] = config.sample.e0;
  summary["threads"] = config.solver.threads;
  try {
    lab::Laboratory lab(config, [&](const std::string& phase, double f, long steps) {
      progress.update(phase, f, steps);
    });
    io::VtkSeries vtk(dir / "vtk");
    if (config.output.vtkEveryStrain > 0.0)
      lab.onSnapshot(
          [&](const Simulation& s, double eps1) {
            const lab::GrainKinematics k = lab.currentKinematics();
            vtk.write(s, eps1,
                      {{{"local_shear_strain", k.localShearStrain}, {"in_band", k.inBand}},
                       {{"displacement", k.displacement}}});
          },
          config.output.vtkEveryStrain);
    lab::PreparationResult prep;
    if (config.sample.packing.empty()) {
      prep = lab.prepare();
    } else {
      Simulation packed;
      io::loadPacking(config.sample.packing, config.sample.density, packed);
      prep = lab.adoptPacking(std::move(packed));
    }
    if (config.output.savePacking)
      io::writeFileAtomic(dir / "packing.txt",
                          io::packingText(lab.simulation(), fmt::format("grainlab prepared sample: e = {:.5f}, p = {} Pa, seed {}",
                                                                        prep.e0, config.test.confiningPressure, config.sample.seed)));
    progress.finish();
    const Simulation& sim = lab.simulation();
    summary["e0"] = finite(prep.e0, "e0");
    // With a given prep_friction_deg there is no search and e0 is simply what that friction gives.
    summary["e0_searched"] = config.sample.packing.empty() && !config.sample.prepFrictionDeg.has_value();
    summary["e0_within_tolerance"] = std::abs(prep.e0 - config.sample.e0) <= config.sample.e0Tolerance;
    summary["prep_friction_deg"] = prep.prepFrictionDeg;
    json search = json::array();
    for (const auto& [mu, e] : prep.search) search.push_back({{"prep_friction_deg", mu}, {"e", e}});
    summary["prep_search"] = search;
    summary["grading"] = gradingJson(prep.grading);
    if (config.contact.model == "rolling-linear") {
      const auto& mu = sim.particles.rollingFriction;
      double sum = 0.0;
      for (double m : mu) sum += m;
      summary["mu_r_mean"] = sum / static_cast<double>(mu.size());
      summary["mu_r_min"] = *std::min_element(mu.begin(), mu.end());
      summary["mu_r_max"] = *std::max_element(mu.begin(), mu.end());
    }
    summary["isotropic_state"] = equilibriumJson(prep.state);
    summary["dt"] = sim.dt;
    summary["dt_critical"] = sim.criticalTimeStep();
    summary["preparation_steps"] = prep.steps;
    if (!opt.quiet)
      std::fprintf(stderr, "prepared: e0 = %.4f (target %.3f, mu_prep = %.2f deg), p = %.1f kPa\n",
                   prep.e0, config.sample.e0, prep.prepFrictionDeg,
                   (prep.state.wallStress.sum() / 3.0) / 1e3);

    std::vector<lab::Record> records;
    long steps = prep.steps;
    if (config.test.type == "triaxial") {
      lab::ShearResult shear = lab.shear();
      progress.finish();
      records = std::move(shear.records);
      steps += shear.steps;
      lab::TriaxialCurves curves;
      for (const auto& r : records) {
        curves.eps1.push_back(r.eps1);
        curves.epsV.push_back(r.epsV);
        curves.sigma1.push_back(r.sigma1);
        curves.sigma3.push_back(0.5 * (r.sigma2 + r.sigma3));
        curves.voidRatio.push_back(r.e);
      }
      const lab::MacroParameters m = lab::computeMacro(curves);
      summary["phi_peak_deg"] = finite(m.phiPeakDeg, "phi_peak_deg");
      summary["eps1_at_peak"] = m.eps1AtPeak;
      summary["q_peak"] = m.qPeak;
      summary["phi_res_deg"] = finite(m.phiResDeg, "phi_res_deg");
      summary["residual_window_eps1"] = {m.residualFrom, records.back().eps1};
      summary["psi_max_deg"] = finite(m.psiMaxDeg, "psi_max_deg");
      summary["eps1_at_psi_max"] = m.eps1AtPsiMax;
      summary["E_MPa"] = finite(m.youngModulus / 1e6, "E_MPa");
      summary["E50_MPa"] = finite(m.e50 / 1e6, "E50_MPa");
      summary["nu"] = finite(m.poisson, "nu");
      summary["cs_q_over_p"] = m.csStressRatio;
      summary["cs_void_ratio"] = m.csVoidRatio;
      summary["strain_rate"] = shear.strainRate;
      summary["inertial_number"] = shear.inertialNumber;
      summary["lateral_stress_max_deviation"] = shear.maxLateralDeviation;
      summary["final_axial_strain"] = records.back().eps1;
      summary["shear_steps"] = shear.steps;
      // Grain rotations at the end of the test, inside and outside the shear band (kinematics.hpp).
      const lab::GrainKinematics k = lab.currentKinematics();
      summary["rotation_mean_deg"] = k.rotationMeanDeg;
      summary["rotation_band_mean_deg"] = k.rotationBandMeanDeg;
      summary["rotation_outside_band_mean_deg"] = k.rotationOutsideMeanDeg;
      summary["band_fraction"] = k.bandFraction;
      // I = rate d50 sqrt(rho/p) with the p measured at each record.
      double inertialMax = 0.0;
      for (const auto& r : records) inertialMax = std::max(inertialMax, r.inertialNumber);
      summary["inertial_number_max"] = inertialMax;
      summary["quasi_static"] = inertialMax <= 1e-3;
      if (inertialMax > 1e-3)
        std::fprintf(stderr, "grainlab: warning: inertial number reached %.2e > 1e-3: the test was not quasi-static\n",
                     inertialMax);
    } else {
      if (config.output.vtkEveryStrain > 0.0) vtk.write(sim, 0.0);
      records.push_back(lab.measure(sim.box.length(2), sim.box.volume(),
                                    Vec3(sim.box.length(0), sim.box.length(1), sim.box.length(2)), 0.0));
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    summary["steps"] = steps;
    summary["wall_seconds"] = wall;
    summary["particle_steps_per_s"] = static_cast<double>(steps) * config.sample.nParticles / wall;
    summary["status"] = "completed";
    io::writeFileAtomic(dir / "timeseries.csv", io::timeseriesCsv(records));
    io::writeFileAtomic(dir / "summary.json", summary.dump(2) + "\n");
    if (config.output.plots) makePlots(dir, opt.quiet);
    if (!opt.quiet) {
      if (summary.contains("phi_peak_deg"))
        std::printf("phi_peak = %.2f deg at eps1 = %.4f, phi_res = %.2f deg, psi_max = %.2f deg, "
                    "E = %.1f MPa, nu = %.3f\n",
                    summary["phi_peak_deg"].get<double>(), summary["eps1_at_peak"].get<double>(),
                    summary["phi_res_deg"].get<double>(), summary["psi_max_deg"].get<double>(),
                    summary["E_MPa"].get<double>(), summary["nu"].get<double>());
      std::printf("%ld steps in %.1f s; results in %s\n", steps, wall, dir.c_str());
    }
    return 0;
  } catch (const SimulationError& e) {
    progress.finish();
    summary["status"] = "failed";
    summary["error"] = e.what();
    summary["wall_seconds"] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    io::writeFileAtomic(dir / "summary.json", summary.dump(2) + "\n");
    throw;
  }
}

}  // namespace grainlab::cli

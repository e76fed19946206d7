#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <random>
#include <string_view>
#include <sstream>
#include <nlohmann/json.hpp>
#include <xxhash.h>

#include "cli/commands.hpp"
#include "cli/progress.hpp"
#include "cli/thread_count.hpp"
#include "core/errors.hpp"
#include "core/kernels/integrate_simd.hpp"
#include "core/state_io.hpp"
#include "io/checkpoint_file.hpp"
#include "io/config.hpp"
#include "io/input_file.hpp"
#include "io/install_paths.hpp"
#include "io/micro_snapshot.hpp"
#include "io/packing.hpp"
#include "io/process.hpp"
#include "io/results.hpp"
#include "io/run_folder.hpp"
#include "io/vtk.hpp"
#include "lab/micro_network.hpp"
#include "lab/grading.hpp"
#include "lab/macro.hpp"
#include "lab/micro_network.hpp"
#include "lab/protocols.hpp"
#include "lab/test_report.hpp"
#include "lab/preflight.hpp"
#include "lab/sphericity.hpp"

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
json stressGapJson(const std::vector<lab::Record>& records, std::size_t peak) {
  std::vector<double> gap, averaging, unbalanced;
  double residual = 0.0;
  auto rel = [](const lab::Record& r) {
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
  auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
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

// A summary number for the console, or "null".
std::string shown(const json& v, const char* format) {
  if (!v.is_number()) return "null";
  char text[64];
  std::snprintf(text, sizeof text, format, v.get<double>());
  return text;
}

// The small-strain probe in the summary (lab/moduli.hpp). E_MPa and nu repeat E0_MPa and nu0 for
// readers of earlier summaries.
// A probe whose nu0 leaves [0, 0.5] or whose E0 is not positive did not measure an isotropic elastic
// response (the probe strain reached slip or collapse): the value is null, the number the probe
// gave stays in nu0_measured / E0_MPa_measured, and a warning says so.
void probeJson(const lab::ModulusProbe& probe, json& s) {
  const bool ok = probe.elastic.has_value();
  s["E0_MPa"] = ok ? json(finite(probe.elastic->young / 1e6, "E0_MPa")) : json(nullptr);
  s["nu0"] = ok ? json(finite(probe.elastic->poisson, "nu0")) : json(nullptr);
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

// JSON text of a summary; a path that is not UTF-8 (config_source) is written with U+FFFD in
// place of its invalid bytes rather than failing the run.
std::string jsonText(const json& j) { return j.dump(2, ' ', false, json::error_handler_t::replace) + "\n"; }

// tools/plot_run.py of the installed data folder, started with an argument vector (no shell: the
// folder name reaches the script byte for byte).
void makePlots(const fs::path& dir, bool quiet) {
  const fs::path script = io::toolScript("plot_run.py");
  if (script.empty()) {
    std::fprintf(stderr,
                 "grainlab: warning: plot_run.py not found in share/grainlab/tools beside the executable; the results "
                 "are complete without plots\n");
    return;
  }
  try {
    const int rc = io::runProcess({GRAINLAB_PYTHON, script.string(), dir.string()},
                                  quiet ? io::ChildOutput::discard() : io::ChildOutput::inherit());
    if (rc != 0)
      std::fprintf(stderr, "grainlab: warning: plotting failed (exit %d); the results are complete without plots\n", rc);
  } catch (const io::FileError& e) {
    std::fprintf(stderr, "grainlab: warning: %s; the results are complete without plots\n", e.what());
  }
}

lab::RunConfig resolveConfig(const RunOptions& opt, bool inputFilesMustExist = true) {
  toml::table table = io::loadConfigTable(opt.config);
  for (const auto& s : opt.overrides) io::applyOverride(table, s);
  if (!opt.outDir.empty()) io::setOutputDir(table, opt.outDir);
  if (opt.threads > 0) io::applyOverride(table, fmt::format("solver.threads={}", opt.threads));
  return io::parseConfig(table, io::configBaseDir(opt.config), inputFilesMustExist);
}

}  // namespace

namespace {
// A packing brings its own particles, whatever sample.n_particles says: a count that differs is
// ignored with this warning (a config that prepared a sample is meant to be reused with
// --set sample.packing=...; config.resolved.toml records the packing's count).
std::string packingCountWarning(const lab::RunConfig& config, std::size_t particles) {
  if (!config.sample.nParticlesGiven || static_cast<std::size_t>(config.sample.nParticles) == particles) return "";
  return fmt::format("sample.n_particles = {} is ignored: sample.packing = {} holds {} particles (a packing brings its "
                     "own)",
                     config.sample.nParticles, io::quotedPath(config.sample.packing), particles);
}

// The config's warnings, printed once everything it names has been read and checked: a refused
// input says one line, its error, and nothing else.
void printConfigWarnings(const lab::RunConfig& config) {
  for (const auto& w : config.warnings) std::fprintf(stderr, "grainlab: warning: %s\n", w.c_str());
}
}  // namespace

std::optional<Simulation> loadInputFiles(const lab::RunConfig& config) {
  if (config.sample.grading.type == "list") {
    const std::vector<double>& list = config.sample.grading.list;  // read with the config (io/list_files.hpp)
    const auto [dMin, dMax] = std::minmax_element(list.begin(), list.end());
    if (config.sample.method == "lattice" && *dMax > 1.01 * *dMin)
      throw InputError(fmt::format("config error: sample.grading.file = {}: diameters from {:g} to {:g} m, but "
                                   "sample.method = \"lattice\" places equal spheres (the grading's d50); allowed: a "
                                   "grading of one size (d_max <= 1.01 d_min)",
                                   io::quotedPath(config.sample.grading.file), *dMin, *dMax));
  }
  if (config.contact.sphericity) {
    const lab::SphericityConfig& sc = *config.contact.sphericity;
    lab::checkRollingFriction(sc.distribution, sc.c, sc.k, sc.file,
                              "contact.sphericity.file");
  }
  if (config.sample.packing.empty()) {
    lab::preflight(config, nullptr);
    printConfigWarnings(config);
    return std::nullopt;
  }
  const io::PackingData packing = io::readPackingFile(config.sample.packing, "sample.packing");
  io::checkPackingGeometry(packing, fmt::format("config error: sample.packing = {}", io::quotedPath(config.sample.packing)));

  Simulation packed;
  io::simulationFromPacking(packing, config.sample.density, packed,
                            fmt::format("config error: sample.packing = {}", io::quotedPath(config.sample.packing)));
  // The boundary is part of the test: a packing made in a cell cannot be sheared between walls, nor the reverse.
  const bool periodic = packed.boundary == Boundary::Periodic;
  if (periodic != (config.test.boundary == "periodic"))
    throw InputError(fmt::format("config error: sample.packing = {}: the packing's boundary is {} but "
                                 "test.boundary = \"{}\"; allowed: the packing's own boundary",
                                 io::quotedPath(config.sample.packing), periodic ? "a periodic cell" : "walls",
                                 config.test.boundary));
  lab::preflight(config, &packed);
  printConfigWarnings(config);
  if (const std::string w = packingCountWarning(config, packed.particles.size()); !w.empty())
    std::fprintf(stderr, "grainlab: warning: %s\n", w.c_str());
  return packed;
}

lab::RunConfig ranConfig(const lab::RunConfig& config, const std::optional<Simulation>& packed) {
  lab::RunConfig ran = config;
  if (packed) {
    if (const std::string w = packingCountWarning(config, packed->particles.size()); !w.empty()) ran.warnings.push_back(w);
    ran.sample.nParticles = static_cast<int>(packed->particles.size());
    ran.sample.nParticlesGiven = true;
    ran.sample.grading = lab::GradingConfig::ofPacking();
  }
  return ran;
}

int checkConfig(const RunOptions& opt) {
  const lab::RunConfig config = resolveConfig(opt);
  const std::optional<Simulation> packed = loadInputFiles(config);
  io::RunFolder::checkReplaceable(config.output.dir);
  std::fputs(io::toTomlString(io::resolvedTable(ranConfig(config, packed))).c_str(), stdout);
  return 0;
}

namespace {

// The status of a run whose curves and summary are written but whose plots and micromechanics
// analysis are not yet (summary.json "status"); "completed" is written last.
constexpr const char* kFinishing = "finishing";

// The analysis of the run's snapshots (micro/analysis.*, class averages, rose diagrams) as
// `grainlab analyse DIR` makes it; a failure there leaves the run's results complete.
void analyseMicro(const fs::path& dir, bool plots) {
  AnalyseOptions a;
  a.dir = dir.string();
  a.plots = plots;
  a.quiet = true;
  try {
    runAnalyse(a);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "grainlab: warning: micromechanics analysis failed (%s); the results are complete without it\n",
                 e.what());
  }
}

// From "finishing" to "completed": plots, the micromechanics analysis, the folder's manifest, and
// last the summary that says "completed". Also what `resume` does for a run killed in between.
void completeResults(const fs::path& dir, const lab::RunConfig& config, json& summary, bool quiet, bool micro) {
  if (config.output.plots) makePlots(dir, quiet);
  if (micro) analyseMicro(dir, config.output.plots);
  summary["status"] = "completed";
  io::RunFolder::writeManifest(dir);
  io::writeFileAtomic(dir / "summary.json", jsonText(summary));
}

// The part of a run after the sample exists: shearing (resumable), results, plots. Shared by
// `run` and `resume`; `summary` already holds what preparation reported.
class RunSession {
 public:
  // Writes into folder.work(); messages name folder.target(), where the results end up.
  RunSession(const lab::RunConfig& config, const io::RunFolder& folder, bool quiet, json summary,
             double secondsBefore, std::vector<double> vtkLabels = {},
             std::vector<io::MicroSnapshotInfo> microSnapshots = {}, lab::ProgressFn observer = {})
      : config_(config), dir_(folder.work()), target_(folder.target()), quiet_(quiet), progress_(quiet),
        summary_(std::move(summary)), secondsBefore_(secondsBefore), t0_(std::chrono::steady_clock::now()),
        vtk_(dir_ / "vtk", std::move(vtkLabels)), micro_(dir_ / "micro", std::move(microSnapshots)),
        lab_(config, [this, observer = std::move(observer)](const std::string& phase, double f, long steps) {
          progress_.update(phase, f, steps);
          if (observer) observer(phase, f, steps);
        }) {
    // The micromechanics snapshots (contact network, for `grainlab analyse` and the rose diagrams)
    // are taken at the VTK snapshots' instants: the start, every vtk_every_strain and the end.
    if (config.output.vtkEveryStrain > 0.0)
      lab_.onSnapshot([this](const Simulation& s, double eps1) { snapshot(s, eps1); }, config.output.vtkEveryStrain);
    if (config.output.checkpointEvery > 0.0)
      lab_.onCheckpoint([this](const lab::Laboratory&) { writeCheckpoint(); }, config.output.checkpointEvery);
  }

  lab::Laboratory& lab() { return lab_; }
  // Per-grain fields of the laboratory's records for the particle snapshots.
  io::PointFields grainFields() const {
    const lab::GrainKinematics k = lab_.currentKinematics();
    const lab::GrainRecords& rec = lab_.grainRecords();
    std::vector<double> path(rec.rotationPath.size());
    for (std::size_t i = 0; i < path.size(); ++i) path[i] = radToDeg(rec.rotationPath[i]);
    return {{{"rotation_deg", k.rotationDeg},
             {"rotation_path_deg", path},
             {"sphericity", rec.sphericity},
             {"local_shear_strain", k.localShearStrain},
             {"in_band", k.inBand}},
            {{"displacement", k.displacement}}};
  }
  void snapshot(const Simulation& s, double eps1) {
    vtk_.write(s, eps1, grainFields());
    if (config_.output.microSnapshots) micro_.write(lab::microNetwork(s), s.stepCount, eps1);
  }
  json& summary() { return summary_; }
  ProgressLine& progress() { return progress_; }
  io::VtkSeries& vtk() { return vtk_; }
  double seconds() const {
    return secondsBefore_ + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
  }

  // checkpoint/state.bin: the run so far (summary, VTK snapshot labels, wall time) and the exact
  // binary state, in the checked container of io/checkpoint_file.hpp, renamed into place.
  void writeCheckpoint() {
    const json record{{"summary", summary_},
                      {"vtk_labels", vtk_.labels()},
                      {"micro_snapshots", io::microSnapshotsJson(micro_.snapshots())},
                      {"wall_seconds", seconds()}};
    std::ostringstream state(std::ios::binary);
    lab_.saveState(state);
    io::writeFileAtomic(dir_ / "checkpoint" / "state.bin", io::encodeCheckpoint(config_, record, state.str()));
  }

  // Shears (from the start, or from where a loaded checkpoint left off) and writes every result.
  int finishShear() {
    if (!lab_.shearStarted()) {
      lab_.beginShear();
      if (config_.output.checkpointEvery > 0.0) writeCheckpoint();
    }
    lab::ShearResult shear = lab_.continueShear();
    progress_.finish();
    const std::vector<lab::Record>& records = shear.records;
    if (config_.test.type == lab::TestType::Oedometer || config_.test.type == lab::TestType::CyclicTriaxial ||
        config_.test.type == lab::TestType::StressPath || config_.test.type == lab::TestType::CyclicSimpleShear)
      return finishReversing(shear);
    const bool simpleShear = config_.test.type == lab::TestType::SimpleShear;
    lab::TriaxialCurves curves;
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
      curves.sigma3.push_back(config_.test.type == lab::TestType::TrueTriaxial ? r.sigma3 : 0.5 * (r.sigma2 + r.sigma3));
      curves.voidRatio.push_back(r.e);
      curves.shearStress.push_back(r.tau);
    }
    lab::MacroSettings criterion;
    criterion.csWindow = config_.test.csWindow.value_or(
        lab::autoCsWindow(simpleShear ? config_.test.finalShearStrain : config_.test.finalAxialStrain));
    const lab::MacroParameters m =
        simpleShear ? lab::computeSimpleShearMacro(curves, criterion) : lab::computeMacro(curves, criterion);
    writeStressDilatancy(lab::stressDilatancy(curves, simpleShear), simpleShear);
    summary_["phi_peak_deg"] = finite(m.phiPeakDeg, "phi_peak_deg");
    summary_["eps1_at_peak"] = m.eps1AtPeak;
    summary_["q_peak"] = m.qPeak;
    summary_["phi_res_deg"] = finite(m.phiResDeg, "phi_res_deg");
    summary_["residual_window_eps1"] = {m.residualFrom, records.back().eps1};
    summary_["psi_max_deg"] = m.psiMaxDeg ? json(finite(*m.psiMaxDeg, "psi_max_deg")) : json(nullptr);
    summary_["psi_max_tan_deg"] = m.psiMaxTanDeg ? json(finite(*m.psiMaxTanDeg, "psi_max_tan_deg")) : json(nullptr);
    summary_["eps1_at_psi_max"] = m.eps1AtPsiMax;
    if (simpleShear) {
      // Simple shear measures a shear modulus; Young's modulus and Poisson's ratio are not measured.
      summary_["G_MPa"] = finite(m.shearModulus / 1e6, "G_MPa");
      summary_["E50_MPa"] = nullptr;
      summary_["E50_method"] = "not measured (simple shear)";
      summary_["final_shear_strain"] = records.back().gamma;
    } else {
      summary_["E50_MPa"] = m.e50 ? json(finite(*m.e50 / 1e6, "E50_MPa")) : json(nullptr);
      summary_["E50_method"] = m.e50 ? "secant from the start of shearing to q = q_peak/2 (q_peak the largest deviator "
                                       "of the monotonic curve), interpolated between records"
                                     : "not measured (q never reached half its peak above its start)";
    }
    moduliFromLoops(lab::unloadReloadLoops(loopEps1, loopQ, loopPhase));
    // The critical state only where the steady-state criterion (lab/macro.hpp) was met; the end of
    // the test always, with its rates, so that a sample still dilating says so.
    const lab::SteadyState& cs = m.steady;
    summary_["residual_q_over_p"] = m.residualStressRatio;
    summary_["residual_void_ratio"] = m.residualVoidRatio;
    summary_["critical_state_reached"] = cs.reached;
    summary_["critical_state_eps1"] = cs.reached ? json(cs.reachedAt) : json(nullptr);
    summary_["cs_q_over_p"] = cs.reached ? json(finite(cs.stressRatio, "cs_q_over_p")) : json(nullptr);
    summary_["cs_void_ratio"] = cs.reached ? json(finite(cs.voidRatio, "cs_void_ratio")) : json(nullptr);
    summary_["cs_p"] = cs.reached ? json(finite(cs.meanStress, "cs_p")) : json(nullptr);
    summary_["end_q_over_p"] = cs.evaluated ? json(finite(cs.endStressRatio, "end_q_over_p")) : json(nullptr);
    summary_["end_void_ratio"] = cs.evaluated ? json(finite(cs.endVoidRatio, "end_void_ratio")) : json(nullptr);
    summary_["end_p"] = cs.evaluated ? json(finite(cs.endMeanStress, "end_p")) : json(nullptr);
    summary_["end_rates"] = cs.evaluated ? json{{"d_q_over_p", cs.endStressRatioRate},
                                                {"d_eps_v", cs.endVolumetricRate},
                                                {"d_e", cs.endVoidRatioRate}}
                                         : json(nullptr);
    summary_["critical_state_window"] = criterion.csWindow;
    summary_["critical_state_criterion"] = fmt::format(
        "every trailing window of {} {} from critical_state_eps1 to the end has |d(q/p)/d eps| <= {}, |d eps_v/d eps| "
        "<= {} and |d e/d eps| <= {} (least-squares slopes, >= {} records); cs_* are the means from "
        "critical_state_eps1 to the end, end_* those of the last window",
        criterion.csWindow, simpleShear ? "shear strain" : "axial strain", criterion.csMaxStressRatioRate,
        criterion.csMaxVolumetricRate, criterion.csMaxVoidRatioRate, criterion.csMinRecords);
    if (lab_.protocol()->undrained()) undrainedKeys(records);
    summary_["strain_rate"] = shear.strainRate;
    summary_["inertial_number"] = shear.inertialNumber;
    summary_["lateral_stress_max_deviation"] = shear.maxLateralDeviation;
    if (config_.test.boundary == "walls")
      summary_["lateral_stress_max_deviation_single_wall"] = shear.maxSingleWallDeviation;
    summary_["shear_pipeline"] = lab_.shearStageNames();
    if (shear.maxLateralDeviation > 0.02)
      std::fprintf(stderr, "grainlab: warning: lateral stress deviated from sigma3 by up to %.1f %% (> 2 %%)\n",
                   100.0 * shear.maxLateralDeviation);
    summary_["final_axial_strain"] = records.back().eps1;
    summary_["shear_steps"] = shear.steps;
    // Micromechanics at the peak (the record nearest the peak's strain) and at the end; the largest
    // energy balance residual over the test (null when no record measured one).
    std::size_t peak = 0;
    for (std::size_t i = 0; i < records.size(); ++i)
      if (std::abs(curves.eps1[i] - m.eps1AtPeak) < std::abs(curves.eps1[peak] - m.eps1AtPeak)) peak = i;
    summary_["micro_at_peak"] = microJson(records[peak]);
    if (!simpleShear) summary_["boundary_contact_gap"] = stressGapJson(records, peak);
    summary_["micro_at_end"] = microJson(records.back());
    std::optional<double> residualMax;
    for (const auto& r : records)
      if (std::isfinite(r.energyResidual)) residualMax = std::max(residualMax.value_or(0.0), std::abs(r.energyResidual));
    summary_["energy_residual_max"] = residualMax ? json(*residualMax) : json(nullptr);
    // Grain rotations at the end of the test, inside and outside the shear band (kinematics.hpp).
    const lab::GrainKinematics k = lab_.currentKinematics();
    summary_["rotation_mean_deg"] = k.rotationMeanDeg;
    summary_["rotation_band_mean_deg"] = k.rotationBandMeanDeg;
    summary_["rotation_outside_band_mean_deg"] = k.rotationOutsideMeanDeg;
    summary_["band_fraction"] = k.bandFraction;
    // I = rate d50 sqrt(rho/p) with the p measured at each record.
    double inertialMax = 0.0;
    for (const auto& r : records) inertialMax = std::max(inertialMax, r.inertialNumber);
    summary_["inertial_number_max"] = inertialMax;
    summary_["quasi_static"] = inertialMax <= 1e-3;
    if (inertialMax > 1e-3)
      std::fprintf(stderr, "grainlab: warning: inertial number reached %.2e > 1e-3: the test was not quasi-static\n",
                   inertialMax);
    return writeResults(records, summary_.value("preparation_steps", 0L) + shear.steps);
  }

  // The undrained keys (lab/test_report.hpp), with a warning where the volume was not held.
  void undrainedKeys(const std::vector<lab::Record>& records) {
    const lab::UndrainedSummary u = lab::undrainedSummary(records, config_.test.confiningPressure, config_.test.ruLimit,
                                                          lab_.protocol()->state.volumeDriftMax);
    summary_["u_max"] = finite(u.uMax, "u_max");
    summary_["p_min"] = finite(u.pMin, "p_min");
    summary_["q_at_phase_transformation"] = u.qAtPhaseTransformation ? json(*u.qAtPhaseTransformation) : json(nullptr);
    summary_["eps1_at_phase_transformation"] =
        u.eps1AtPhaseTransformation ? json(*u.eps1AtPhaseTransformation) : json(nullptr);
    summary_["liquefied"] = u.liquefied;
    volumeDriftKeys(u.volumeDriftMax);
  }

  // volume_drift_max of an undrained test, with a warning above what the boundary should hold.
  void volumeDriftKeys(double drift) {
    summary_["volume_drift_max"] = drift;
    const double allowed = config_.test.boundary == "periodic" ? 1e-6 : 1e-5;
    if (drift > allowed)
      summary_["warnings"].push_back(
          fmt::format("the volume drifted by up to {:.3g} during the undrained test (> {:g})", drift, allowed));
  }

  // Oedometer and cyclic triaxial: their own macro-values (lab/test_report.hpp), not a monotonic
  // curve's peak and residual.
  int finishReversing(const lab::ShearResult& shear) {
    const std::vector<lab::Record>& records = shear.records;
    const lab::ShearProtocol& protocol = *lab_.protocol();
    if (config_.test.type == lab::TestType::Oedometer) {
      const lab::OedometerSummary o = lab::oedometerSummary(records, config_.test.confiningPressure);
      auto opt = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
      summary_["K0"] = opt(o.k0);
      summary_["K0_unloading"] = opt(o.k0Unloading);
      summary_["Cc"] = opt(o.cc);
      summary_["Cs"] = opt(o.cs);
      summary_["sigma_v_max"] = o.sigmaVMax;
      summary_["oedometer_method"] = fmt::format(
          "lateral strain zero; K0 = sigma_h/sigma_v averaged over the {} loading records with sigma_v >= sqrt(p0 "
          "sigma_v_max) (the start is isotropic), K0_unloading at the last record; Cc, Cs = -de/dlog10(sigma_v), "
          "least-squares over the same loading records and over the {} unloading records",
          o.loadingRecords, o.unloadingRecords);
    } else if (config_.test.type == lab::TestType::CyclicSimpleShear) {
      const lab::ProtocolState& ps = protocol.state;
      const std::size_t n = static_cast<std::size_t>(ps.amplitudesDone);
      json amplitudes = json::array(), g = json::array(), ratio = json::array(), damping = json::array();
      // Gmax: the secant modulus at the smallest amplitude.
      const double gmax = n > 0 ? ps.secantModulus[0] : 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        amplitudes.push_back(ps.measuredAmplitude[i]);
        g.push_back(ps.secantModulus[i] / 1e6);
        ratio.push_back(gmax > 0.0 ? json(ps.secantModulus[i] / gmax) : json(nullptr));
        damping.push_back(ps.dampingRatio[i]);
      }
      summary_["shear_strain_amplitudes"] = amplitudes;
      summary_["G_secant_MPa"] = g;
      summary_["G_over_Gmax"] = ratio;
      summary_["damping_ratio"] = damping;
      summary_["Gmax_MPa"] = n > 0 ? json(gmax / 1e6) : json(nullptr);
      summary_["cycles_per_amplitude"] = config_.test.cyclesPerAmplitude;
      summary_["G_method"] = fmt::format(
          "per amplitude, over its last of {} cycles: G = (tau_max - tau_min)/(gamma_max - gamma_min) (secant), "
          "damping ratio = W_D/(4 pi W_S), W_D the loop area (integral of tau dgamma every step), W_S = G "
          "gamma_a^2/2 with gamma_a the half-range of gamma; shear_strain_amplitudes are the measured half-ranges; "
          "Gmax = G at the smallest amplitude",
          config_.test.cyclesPerAmplitude);
      if (n > 0 && config_.test.shearStrainAmplitudes[0] > 1e-5)
        summary_["warnings"].push_back(fmt::format(
            "the smallest amplitude {} is above 1e-5: Gmax (G at that amplitude) may be below the elastic "
            "small-strain modulus",
            config_.test.shearStrainAmplitudes[0]));
      summary_["ru_max"] = protocol.undrained() ? json(ps.ruMax) : json(nullptr);
      if (protocol.undrained()) volumeDriftKeys(ps.volumeDriftMax);
    } else if (config_.test.type == lab::TestType::StressPath) {
      const lab::ProtocolState& ps = protocol.state;
      const double sEnd = config_.test.path.back().s;
      summary_["path_points"] = config_.test.path.size();
      summary_["path_source"] = config_.test.pathSource.empty() ? json(nullptr) : json(config_.test.pathSource);
      summary_["path_completed"] = !ps.pathFailed;
      summary_["path_s_reached"] = ps.path;
      summary_["path_stress_deviation_max"] = ps.stressDeviationMax;
      summary_["path_method"] =
          "s advances at test.axial_strain_rate; per segment each axis moves linearly in s from where the segment "
          "began to the point's target; path_stress_deviation_max = max |sigma - target| / test.confining_pressure "
          "of a stress-controlled axis over every step (the servo's lag)";
      if (ps.pathFailed)
        summary_["warnings"].push_back(fmt::format(
            "the stress path stopped at s = {:.6g} of {:.6g}: a strain reached test.final_axial_strain = {} (a stress "
            "target beyond what the sample carries)",
            ps.path, sEnd, config_.test.finalAxialStrain));
    } else {
      const lab::CyclicSummary c = lab::cyclicSummary(protocol.state);
      summary_["n_cycles_to_liquefaction"] = c.cyclesToLiquefaction ? json(*c.cyclesToLiquefaction) : json(nullptr);
      summary_["ru_max"] = protocol.undrained() ? json(c.ruMax) : json(nullptr);
      summary_["cycles"] = c.cycles;
      summary_["double_amplitude_strain_max"] = c.doubleAmplitudeMax;
      summary_["csr"] = config_.test.csr;
      summary_["liquefaction_criterion"] = fmt::format(
          "{}double-amplitude axial strain of a cycle >= {}; n_cycles_to_liquefaction counts the half cycle it "
          "happened in (0.5: the first compression)",
          protocol.undrained() ? fmt::format("ru = 1 - p'/p0 >= {} or ", config_.test.ruLimit) : std::string(),
          config_.test.liquefactionDaStrain);
      if (protocol.undrained()) volumeDriftKeys(protocol.state.volumeDriftMax);
    }
    summary_["strain_rate"] = shear.strainRate;
    summary_["inertial_number"] = shear.inertialNumber;
    summary_["shear_pipeline"] = lab_.shearStageNames();
    summary_["final_axial_strain"] = records.back().eps1;
    summary_["shear_steps"] = shear.steps;
    summary_["micro_at_end"] = microJson(records.back());
    double inertialMax = 0.0;
    for (const auto& r : records) inertialMax = std::max(inertialMax, r.inertialNumber);
    summary_["inertial_number_max"] = inertialMax;
    summary_["quasi_static"] = inertialMax <= 1e-3;
    return writeResults(records, summary_.value("preparation_steps", 0L) + shear.steps);
  }

  // stress_dilatancy.csv: Rowe's data of the monotonic curve (lab::stressDilatancy).
  void writeStressDilatancy(const lab::StressDilatancy& sd, bool simpleShear) {
    std::string csv = simpleShear ? "gamma,D,tau_over_sigma_n\n" : "eps1,D,q_over_p,R\n";
    for (std::size_t i = 0; i < sd.strain.size(); ++i) {
      if (!std::isfinite(sd.dilatancy[i]) || !std::isfinite(sd.stressRatio[i])) continue;
      csv += fmt::format("{:.8g},{:.8g},{:.8g}", sd.strain[i], sd.dilatancy[i], sd.stressRatio[i]);
      if (!simpleShear) csv += fmt::format(",{:.8g}", sd.principalRatio[i]);
      csv += "\n";
    }
    io::writeFileAtomic(dir_ / "stress_dilatancy.csv", csv);
  }

  int finishIsotropic() {
    const Simulation& sim = lab_.simulation();
    if (config_.output.vtkEveryStrain > 0.0) snapshot(sim, 0.0);
    const std::vector<lab::Record> records{lab_.measure()};
    return writeResults(records, summary_.value("preparation_steps", 0L));
  }

  // Eur of each unload–reload loop (lab/moduli.hpp); null when the test had no loop.
  void moduliFromLoops(const std::vector<lab::UnloadReloadLoop>& loops) {
    if (loops.empty()) {
      summary_["Eur_MPa"] = nullptr;
      summary_["Eur_method"] = "not measured (no test.unload_reload_at)";
      return;
    }
    json eur = json::array(), at = json::array(), relaxed = json::array(), measured = json::array();
    bool rejected = false;
    for (const auto& l : loops) {
      // A reload secant that is not positive (the sample kept collapsing through the loop) is not an
      // unload-reload modulus: null, with the number in Eur_MPa_measured and a warning.
      const bool positive = l.eur && *l.eur > 0.0;
      measured.push_back(l.eur ? json(finite(*l.eur / 1e6, "Eur_MPa")) : json(nullptr));
      eur.push_back(positive ? measured.back() : json(nullptr));
      if (l.eur && !positive) {
        rejected = true;
        summary_["warnings"].push_back(fmt::format(
            "Eur = {:.4g} MPa of the loop at eps1 = {:.4g} is not positive (the reload did not stiffen the sample); "
            "reported as null (Eur_MPa_measured keeps it)",
            *l.eur / 1e6, l.eps1Reversal));
      }
      at.push_back(l.eps1Reversal);
      relaxed.push_back(l.restRelaxation ? json(finite(*l.restRelaxation, "Eur_rest_q_relaxation")) : json(nullptr));
    }
    summary_["Eur_MPa"] = eur;
    if (rejected) summary_["Eur_MPa_measured"] = measured;
    summary_["Eur_at_eps1"] = at;
    // The fraction of q lost at constant strain during the rest before each unload (null: no rest).
    summary_["Eur_rest_q_relaxation"] = relaxed;
    summary_["Eur_method"] = fmt::format(
        "per loop: secant of the reload branch, from the turning point (unloaded to q = {} q at reversal) to where "
        "the reload regains the reversal strain; platens at {} of the loading speed{}",
        config_.test.unloadToQFraction, lab::Laboratory::kLoopSpeedFactor,
        config_.test.loopRest ? fmt::format("; before each unload the platens stood still until the unbalanced-force "
                                            "ratio was below {} (q at reversal: after that rest)",
                                            lab::Laboratory::kProbeUnbalanced)
                              : std::string());
  }

  // A failed (or interrupted) run still leaves a summary saying so (and nothing non-finite).
  void writeFailure(const SimulationError& e) {
    progress_.finish();
    summary_["status"] = dynamic_cast<const RunInterrupted*>(&e) ? "interrupted" : "failed";
    summary_["error"] = e.what();
    summary_["wall_seconds"] = seconds();
    io::writeFileAtomic(dir_ / "summary.json", jsonText(summary_));
  }

 private:
  int writeResults(const std::vector<lab::Record>& records, long steps) {
    const double wall = seconds();
    summary_["steps"] = steps;
    summary_["wall_seconds"] = wall;
    // The particles simulated (a packing file brings its own number, whatever sample.n_particles says).
    summary_["particle_steps_per_s"] =
        static_cast<double>(steps) * static_cast<double>(lab_.simulation().particles.size()) / wall;
    // "finishing" until the plots and the micromechanics analysis are written too: a run killed
    // while plotting is not reported complete, and `resume` finishes what is missing.
    summary_["status"] = kFinishing;
    io::TimeseriesColumns columns = io::timeseriesColumns(config_);
    columns.micro = lab_.microColumnNames();
    io::writeFileAtomic(dir_ / "timeseries.csv", io::timeseriesCsv(records, columns));
    io::writeFileAtomic(dir_ / "summary.json", jsonText(summary_));
    completeResults(dir_, config_, summary_, quiet_, !micro_.snapshots().empty());
    if (!quiet_) {
      if (summary_.contains("G_MPa"))
        std::printf("phi_peak = %.2f deg at gamma = %.4f, phi_res = %.2f deg, psi_max = %s deg, G = %.1f MPa\n",
                    summary_["phi_peak_deg"].get<double>(), summary_["eps1_at_peak"].get<double>(),
                    summary_["phi_res_deg"].get<double>(), shown(summary_["psi_max_deg"], "%.2f").c_str(),
                    summary_["G_MPa"].get<double>());
      else if (summary_.contains("phi_peak_deg"))
        std::printf("phi_peak = %.2f deg at eps1 = %.4f, phi_res = %.2f deg, psi_max = %s deg, E0 = %s MPa, "
                    "nu0 = %s, E50 = %s MPa\n",
                    summary_["phi_peak_deg"].get<double>(), summary_["eps1_at_peak"].get<double>(),
                    summary_["phi_res_deg"].get<double>(), shown(summary_["psi_max_deg"], "%.2f").c_str(),
                    shown(summary_["E0_MPa"], "%.1f").c_str(), shown(summary_["nu0"], "%.3f").c_str(),
                    shown(summary_["E50_MPa"], "%.1f").c_str());
      if (summary_.contains("critical_state_reached")) {
        if (summary_["critical_state_reached"].get<bool>())
          std::printf("critical state reached at %s = %.4f: q/p = %.3f, e = %.4f\n",
                      summary_.contains("G_MPa") ? "gamma" : "eps1", summary_["critical_state_eps1"].get<double>(),
                      summary_["cs_q_over_p"].get<double>(), summary_["cs_void_ratio"].get<double>());
        else if (summary_["end_rates"].is_object())
          std::printf("critical state not reached: at the end d eps_v/d eps = %.3f, d(q/p)/d eps = %.2f (q/p = %.3f, e = "
                      "%.4f)\n",
                      summary_["end_rates"]["d_eps_v"].get<double>(), summary_["end_rates"]["d_q_over_p"].get<double>(),
                      summary_["end_q_over_p"].get<double>(), summary_["end_void_ratio"].get<double>());
        else
          std::printf("critical state not reached: the test is shorter than the criterion's window\n");
      }
      std::printf("%ld steps in %.1f s; results in %s\n", steps, wall, io::printable(target_.native(), 240).c_str());
    }
    return 0;
  }

  // The micromechanics columns of one record by name, null where not measurable.
  json microJson(const lab::Record& r) const {
    json out = json::object();
    const std::vector<std::string> names = lab_.microColumnNames();
    for (std::size_t k = 0; k < names.size(); ++k)
      out[names[k]] = std::isfinite(r.micro.at(k)) ? json(r.micro[k]) : json(nullptr);
    out["energy_residual"] = std::isfinite(r.energyResidual) ? json(r.energyResidual) : json(nullptr);
    out["eps1"] = r.eps1;
    return out;
  }

  const lab::RunConfig& config_;
  fs::path dir_, target_;
  bool quiet_;
  ProgressLine progress_;
  json summary_;
  double secondsBefore_;
  std::chrono::steady_clock::time_point t0_;
  io::VtkSeries vtk_;
  io::MicroSnapshotSeries micro_;
  lab::Laboratory lab_;
};

int finish(RunSession& session, const lab::RunConfig& config) {
  try {
    return config.test.type == lab::TestType::Isotropic ? session.finishIsotropic() : session.finishShear();
  } catch (const SimulationError& e) {
    session.writeFailure(e);
    throw;
  }
}

// Runs `body` (which writes into folder.work()) and puts its results in place; on the way out of a
// refused input, or of a failed re-run, removes what it wrote (the earlier results stay as they were).
int inFolder(io::RunFolder& folder, const std::function<int()>& body) {
  int rc = 0;
  try {
    rc = body();
  } catch (const InputError&) {
    folder.discard();
    throw;
  } catch (const SimulationError& e) {
    if (!folder.staged()) throw;  // a new folder keeps the failed run's summary
    folder.discard();
    throw SimulationError(fmt::format("{}; the earlier results in {} are left as they were", e.what(),
                                      io::quotedPath(folder.target())));
  } catch (...) {
    if (folder.staged()) folder.discard();
    throw;
  }
  folder.commit();
  return rc;
}

}  // namespace

// solver.threads, or fewer on a machine whose cores other processes keep busy (cli/thread_count.hpp);
// the summary and the resolved config keep the requested count: results do not depend on it.
static void useThreads(int requested) {
  const ThreadChoice choice = chooseThreads(requested);
  if (!choice.warning.empty()) std::fprintf(stderr, "%s\n", choice.warning.c_str());
  setOpenMPThreads(choice.threads);
}

namespace {

// A new run's identity (128 random bits, hex): in config.resolved.toml's first line, the summary and
// every checkpoint, so that `resume` continues a checkpoint only in the folder of its own run. It
// does not enter the simulation.
std::string newRunId() {
  std::random_device rd;
  std::string id;
  for (int k = 0; k < 4; ++k) id += fmt::format("{:08x}", static_cast<std::uint32_t>(rd()));
  return id;
}

constexpr std::string_view kRunIdPrefix = "# grainlab run ";

// The run id in the first line of a config.resolved.toml ("" for a file without one).
std::string runIdOf(const fs::path& resolvedConfig) {
  const std::string text = io::readInputFile(resolvedConfig, "resume: config.resolved.toml", io::kMaxConfigBytes);
  if (text.compare(0, kRunIdPrefix.size(), kRunIdPrefix) != 0) return "";
  const auto end = text.find_first_of(" \n", kRunIdPrefix.size());
  return text.substr(kRunIdPrefix.size(), end == std::string::npos ? std::string::npos : end - kRunIdPrefix.size());
}

std::string xxh64Hex(std::string_view bytes) { return fmt::format("{:016x}", XXH64(bytes.data(), bytes.size(), 0)); }

// What binds a checkpoint to the folder it is resumed in: the run id of config.resolved.toml and the
// packing the run saved there. A config and checkpoint copied from another run's folder (the folder
// then mixing the packing of one run with the results of another) are refused.
void checkCheckpointBelongsToFolder(const json& checkpointSummary, const fs::path& dir, const fs::path& stateFile) {
  auto refuse = [&](const std::string& why) {
    return InputError(fmt::format("checkpoint {}: {}; a checkpoint resumes only in the results folder of its own run",
                                  io::quotedPath(stateFile), why));
  };
  const std::string folderId = runIdOf(dir / "config.resolved.toml");
  const std::string id = checkpointSummary.value("run_id", std::string());
  if (id != folderId)
    throw refuse(fmt::format("belongs to run {} but config.resolved.toml beside it is of run {}", id.empty() ? "(none)" : id,
                             folderId.empty() ? "(none)" : folderId));
  const std::string packing = checkpointSummary.value("packing_xxh64", std::string());
  if (!packing.empty()) {
    std::error_code ec;
    if (!fs::exists(dir / "packing.txt", ec)) throw refuse("the run saved packing.txt, which is not in the folder any more");
    const std::string actual =
        xxh64Hex(io::readInputFile(dir / "packing.txt", "resume: packing.txt", io::kMaxPackingBytes));
    if (actual != packing)
      throw refuse(fmt::format("packing.txt in the folder (xxh64 {}) is not the one the run saved (xxh64 {})", actual, packing));
  }
}

}  // namespace

int runLab(const RunOptions& opt) { return runResolved(resolveConfig(opt), opt, {}); }

int runResolved(const lab::RunConfig& requested, const RunOptions& opt, const lab::ProgressFn& observer) {
  // Every input file is read and checked before the results folder is touched.
  std::optional<Simulation> packed = loadInputFiles(requested);
  const lab::RunConfig config = ranConfig(requested, packed);  // with a packing: its n_particles and grading
  useThreads(config.solver.threads);
  io::RunFolder folder = io::RunFolder::forRun(config.output.dir);
  return inFolder(folder, [&] {
    const fs::path dir = folder.work();
    const std::string runId = newRunId();
    io::writeFileAtomic(dir / "config.resolved.toml",
                        fmt::format("{}{}\n", kRunIdPrefix, runId) + io::toTomlString(io::resolvedTable(config)));

    json summary;
    summary["run_id"] = runId;
    summary["config_source"] = opt.config;
    summary["n_particles"] = packed ? packed->particles.size() : static_cast<std::size_t>(config.sample.nParticles);
    summary["confining_pressure"] = config.test.confiningPressure;
    summary["test"] = std::string(lab::name(config.test.type));
    if (lab::info(config.test.type).drainage)
      summary["drainage"] = config.test.drainage == lab::Drainage::Undrained ? "undrained" : "drained";
    summary["e0_target"] = config.sample.e0;
    summary["threads"] = config.solver.threads;
    summary["simd_target"] = kernels::simdTarget();  // GRAINLAB_SIMD; the results do not depend on it
    for (const auto& w : config.warnings) summary["warnings"].push_back(w);
    RunSession session(config, folder, opt.quiet, summary, 0.0, {}, {}, observer);
    lab::Laboratory& lab = session.lab();
    try {
      const lab::PreparationResult prep = packed ? lab.adoptPacking(std::move(*packed)) : lab.prepare();
      session.progress().finish();
      const Simulation& sim = lab.simulation();
      json& s = session.summary();
      if (config.output.savePacking) {
        const std::string text = io::packingText(io::packingFromSimulation(
            sim, fmt::format("grainlab prepared sample: e = {:.5f}, p = {} Pa, seed {}", prep.e0,
                             config.test.confiningPressure, config.sample.seed)));
        io::writeFileAtomic(dir / "packing.txt", text);
        s["packing_xxh64"] = xxh64Hex(text);
      }
      s["n_particles"] = sim.particles.size();
      s["e0"] = finite(prep.e0, "e0");
      // With a given prep_friction_deg there is no search and e0 is simply what that friction gives.
      // Only compaction searches (growth, lattice, deposition and under-compaction reach their own e0).
      s["e0_searched"] = config.sample.packing.empty() && !config.sample.prepFrictionDeg.has_value() &&
                         (config.sample.method == "compaction" || config.sample.method == "loose-moment-free");
      s["e0_within_tolerance"] = std::abs(prep.e0 - config.sample.e0) <= config.sample.e0Tolerance;
      if (!s["e0_within_tolerance"].get<bool>() && !packed.has_value() &&
          (config.sample.method == "compaction" || config.sample.method == "loose-moment-free" ||
           config.sample.method == "under-compaction")) {
        // A missed e0 target (a given prep_friction_deg is not searched) is reported, never silent.
        const std::string w = fmt::format(
            "e0 = {:.4f} misses sample.e0 = {} by more than sample.e0_tolerance = {}{}", prep.e0, config.sample.e0,
            config.sample.e0Tolerance,
            config.sample.method == "under-compaction"
                ? std::string(" (under-compaction tamps the layers to e0; consolidation to p then compresses them)")
            : config.sample.prepFrictionDeg
                ? fmt::format(" (sample.prep_friction_deg = {} is fixed, not searched)", *config.sample.prepFrictionDeg)
                : std::string());
        std::fprintf(stderr, "grainlab: warning: %s\n", w.c_str());
        s["warnings"].push_back(w);
      }
      // A packing file is taken as it is: no preparation friction was used.
      s["prep_friction_deg"] = prep.prepFrictionDeg ? json(*prep.prepFrictionDeg) : json(nullptr);
      if (packed.has_value())
        s["packing_friction_deg"] =
            config.sample.packingFrictionDeg ? json(*config.sample.packingFrictionDeg) : json(nullptr);
      s["preparation_method"] = config.sample.packing.empty() ? config.sample.method : "packing file";
      json search = json::array();
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
      // Coordination after preparation; a sample standing at Z < 2 is a house of cards (tenuous
      // arches held by contact moments) that collapses at the first load.
      s["Z"] = prep.coordination.Z;
      s["Z_mech"] = prep.coordination.Zmech ? json(*prep.coordination.Zmech) : json(nullptr);
      s["rattler_fraction"] = prep.coordination.rattlerFraction;
      s["house_of_cards"] = prep.coordination.Z < 2.0;
      if (prep.coordination.Z < 2.0)
        std::fprintf(stderr, "grainlab: warning: the prepared sample stands at Z = %.2f < 2 (a house of cards)\n",
                     prep.coordination.Z);
      // Fabric of the prepared sample: R = <n (x) n> over particle-particle contacts and its
      // anisotropy a_r = 15/2 dev R (docs/micromechanics.md); a deposited sample prefers vertical
      // contacts (a_r_zz > 0). Null without contacts.
      {
        const lab::MicroAnalysis micro = lab.microAnalyzer().analyse(lab::microNetwork(sim));
        json fabric;
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
        s["fabric_after_preparation"] = fabric;
      }
      if (prep.deposition) {
        const lab::DepositionReport& d = *prep.deposition;
        s["deposition"] = {{"drop_height", d.dropHeight}, {"cloud_height", d.cloudHeight},
                           {"cloud_solid_fraction", d.cloudSolidFraction}, {"width", d.width},
                           {"bed_height", d.bedHeight}, {"settled_void_ratio", d.settledVoidRatio},
                           {"settled_Z", d.settledCoordination},
                           {"settled_a_r_zz", d.settledFabricZz ? json(*d.settledFabricZz) : json(nullptr)},
                           {"gravity_work", d.gravityWork},
                           {"steps", d.steps}};
      }
      if (prep.underCompaction) {
        const lab::UnderCompactionReport& u = *prep.underCompaction;
        auto profile = [](const std::vector<double>& e) {
          json out = json::array();
          for (double v : e) out.push_back(std::isfinite(v) ? json(v) : json(nullptr));
          return out;
        };
        s["under_compaction"] = {{"layers", u.layers}, {"under_compaction", u.underCompaction},
                                 {"target_void_ratio", u.targetVoidRatio}, {"width", u.width},
                                 {"target_heights", u.targetHeights}, {"tamped_void_ratio", u.tampedVoidRatio},
                                 {"tamper_stress", u.tamperStress}, {"tamper_reached", u.tamperReached}, {"tamper_speed", u.tamperSpeed},
                                 {"void_ratio", u.voidRatio}, {"Z", u.coordination},
                                 {"a_r_zz", u.fabricZz ? json(*u.fabricZz) : json(nullptr)},
                                 {"void_ratio_profile", profile(u.voidRatioProfile)},
                                 {"prepared_void_ratio_profile", profile(u.preparedProfile)},
                                 {"gravity_work", u.gravityWork}, {"steps", u.steps}};
        // A layer a few grains thick is mostly wall: its void ratio is the wall's, not the tamping's.
        const double layerThickness = u.targetHeights.empty() ? 0.0 : u.targetHeights.back() / u.layers;
        s["under_compaction"]["layer_thickness_d50"] = layerThickness / prep.grading.d50;
        if (layerThickness < 3.0 * prep.grading.d50) {
          const std::string w = fmt::format(
              "sample.layers = {}: each layer is {:.1f} d50 thick (under 3); more particles or fewer layers",
              u.layers, layerThickness / prep.grading.d50);
          std::fprintf(stderr, "grainlab: warning: %s\n", w.c_str());
          s["warnings"].push_back(w);
        }
        const long stalled = std::count(u.tamperReached.begin(), u.tamperReached.end(), false);
        if (stalled > 0) {
          const std::string w = fmt::format(
              "under-compaction: the tamper stalled at the confining pressure on {} of {} layers (they stay looser "
              "than their target)", stalled, u.layers);
          std::fprintf(stderr, "grainlab: warning: %s\n", w.c_str());
          s["warnings"].push_back(w);
        }
      }
      s["dt"] = sim.dt;
      s["dt_critical"] = sim.criticalTimeStep();
      s["preparation_steps"] = prep.steps;
      if (!prep.growth.empty()) {
        // [O]'s growth curve: Z (and its spread over the particles) and packing fraction per stage.
        json curve = json::array();
        for (const auto& g : prep.growth)
          curve.push_back({{"eccentricity", g.eccentricity}, {"Z", g.coordination}, {"Z_std", g.coordinationStd},
                           {"packing_fraction", g.packingFraction}});
        s["growth_curve"] = curve;
      }
      probeJson(lab.probeModuli(), s);
      if (!opt.quiet) {
        const std::string how =
            !config.sample.packing.empty()            ? std::string("from the packing file")
            : config.sample.method == "deposition"    ? fmt::format("deposition at {:.1f} deg: no target",
                                                                        prep.prepFrictionDeg.value_or(0.0))
            : config.sample.method == "under-compaction"
                ? fmt::format("{} layers tamped to e {:.3f}, U = {}", config.sample.layers, config.sample.e0,
                              config.sample.underCompaction)
            : config.sample.method != "compaction"    ? fmt::format("frictionless {}: no target", config.sample.method)
                                                      : fmt::format("target {:.3f}, mu_prep = {:.2f} deg", config.sample.e0,
                                                                    prep.prepFrictionDeg.value_or(0.0));
        std::fprintf(stderr, "prepared: e0 = %.4f (%s), p = %.1f kPa\n", prep.e0, how.c_str(),
                     (prep.state.boundaryStress.sum() / 3.0) / 1e3);
      }
    } catch (const SimulationError& e) {
      session.writeFailure(e);
      throw;
    }
    return finish(session, config);
  });
}

int resumeLab(const ResumeOptions& opt) {
  io::RunFolder folder = io::RunFolder::forResume(opt.dir);
  const fs::path dir = folder.work();
  const fs::path stateFile = dir / "checkpoint" / "state.bin";
  std::error_code ec;
  if (!fs::exists(dir / "config.resolved.toml", ec))
    throw InputError(fmt::format("resume {}: no config.resolved.toml there (not a grainlab results folder)",
                                 io::quotedPath(opt.dir)));
  if (fs::exists(dir / "summary.json", ec)) {
    json done = json::parse(io::readInputFile(dir / "summary.json", "resume: summary.json", io::kMaxConfigBytes),
                            nullptr, false);
    const std::string status = done.is_object() && done.contains("status") && done["status"].is_string()
                                   ? done["status"].get<std::string>() : std::string();
    if (status == "completed") {
      // A re-run killed after completing but before its results were put in place: put them there.
      if (folder.staged()) inFolder(folder, [] { return 0; });
      if (!opt.quiet) std::printf("%s: run already completed\n", io::printable(folder.target().native(), 240).c_str());
      return 0;
    }
    if (status == kFinishing) {
      // Killed while plotting or analysing: the curves and summary are there, finish the rest.
      RunOptions resolved;
      resolved.config = (dir / "config.resolved.toml").string();
      const lab::RunConfig config = resolveConfig(resolved, /*inputFilesMustExist=*/false);  // never read by resume
      return inFolder(folder, [&] {
        completeResults(dir, config, done, opt.quiet, fs::exists(dir / "micro" / "snapshots.csv", ec));
        if (!opt.quiet)
          std::printf("%s: plots and analysis finished; run completed\n", io::printable(folder.target().native(), 240).c_str());
        return 0;
      });
    }
  }
  if (!fs::exists(stateFile, ec))
    throw InputError(fmt::format("resume {}: no checkpoint/state.bin (checkpoints are written during shearing, "
                                 "every output.checkpoint_every of axial strain)",
                                 io::quotedPath(opt.dir)));
  RunOptions resolved;
  resolved.config = (dir / "config.resolved.toml").string();
  const lab::RunConfig config = resolveConfig(resolved, /*inputFilesMustExist=*/false);  // never read by resume
  const io::Checkpoint checkpoint = io::readCheckpointFile(stateFile);
  io::checkCheckpointBelongs(checkpoint, stateFile, config, opt.allowOlderVersion);
  checkCheckpointBelongsToFolder(checkpoint.record["summary"], dir, stateFile);
  useThreads(config.solver.threads);
  const json& record = checkpoint.record;
  // Checkpoints of runs before the micromechanics snapshots have no list: the run numbers from 0.
  RunSession session(config, folder, opt.quiet, record["summary"], record["wall_seconds"].get<double>(),
                     record["vtk_labels"].get<std::vector<double>>(),
                     record.contains("micro_snapshots")
                         ? io::microSnapshotsFromJson(record["micro_snapshots"], fmt::format("resume {}", io::quotedPath(opt.dir)))
                         : std::vector<io::MicroSnapshotInfo>{});
  try {
    stateio::MemoryInput in(checkpoint.state);
    session.lab().loadState(in);
    // Laboratory::loadState validated the engine's state (Simulation::loadState) and the lab's own.
    if (in.bytesLeft() != 0) throw stateio::StateError(fmt::format("{} bytes left over after the state", in.bytesLeft()));
  } catch (const std::exception& e) {
    throw InputError(fmt::format("checkpoint {}: cannot be resumed: {}", io::quotedPath(stateFile), e.what()));
  }
  if (!opt.quiet)
    std::fprintf(stderr, "resuming %s at step %ld\n", io::printable(dir.native(), 240).c_str(),
                 session.lab().simulation().stepCount);
  // A resumed re-run replaces the earlier results only once complete, as the run would have.
  return inFolder(folder, [&] { return finish(session, config); });
}

}  // namespace grainlab::cli

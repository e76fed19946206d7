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
#include "lab/run_report.hpp"
#include "lab/test_report.hpp"
#include "lab/preflight.hpp"
#include "lab/sphericity.hpp"

namespace grainlab::cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// A summary number for the console, or "null".
std::string shown(const json& v, const char* format) {
  if (!v.is_number()) return "null";
  char text[64];
  std::snprintf(text, sizeof text, format, v.get<double>());
  return text;
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
    const lab::GrainKinematics increment = lab_.incrementKinematics();
    const lab::GrainRecords& rec = lab_.grainRecords();
    std::vector<double> path(rec.rotationPath.size());
    for (std::size_t i = 0; i < path.size(); ++i) path[i] = radToDeg(rec.rotationPath[i]);
    return {{{"rotation_deg", k.rotationDeg},
             {"rotation_path_deg", path},
             {"sphericity", rec.sphericity},
             {"local_shear_strain", k.localShearStrain},
             {"in_band", k.inBand},
             {"strain_increment", increment.localShearStrain},
             {"in_band_increment", increment.inBand}},
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
    const lab::ShearReport report = lab::reportShear(config_, shear, lab_, summary_);
    for (const auto& w : report.warnings) std::fprintf(stderr, "grainlab: warning: %s\n", w.c_str());
    if (report.stressDilatancy) writeStressDilatancy(*report.stressDilatancy, report.simpleShear);
    return writeResults(shear.records, summary_.value("preparation_steps", 0L) + shear.steps);
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
    // What the run had: fewer than requested where other processes kept cores busy (useThreads);
    // the wall time and the speed are for this count.
    summary["threads_used"] = omp_get_max_threads();
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
      for (const auto& w : lab::reportPreparation(config, prep, lab, packed.has_value(), s))
        std::fprintf(stderr, "grainlab: warning: %s\n", w.c_str());
      lab::reportProbe(lab.probeModuli(), s);
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
  json summary = record["summary"];
  summary["threads_used"] = omp_get_max_threads();  // this session's (the wall time spans both)
  // Checkpoints of runs before the micromechanics snapshots have no list: the run numbers from 0.
  RunSession session(config, folder, opt.quiet, summary, record["wall_seconds"].get<double>(),
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

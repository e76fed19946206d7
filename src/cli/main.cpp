// The grainlab command line (docs/interface.md). Exit codes: 0 success, 2 bad input, 1 failed run.
#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <omp.h>

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli/commands.hpp"
#include "cli/thread_count.hpp"
#include "core/errors.hpp"
#include "io/input_file.hpp"
#include "io/presets.hpp"

namespace {

// Every error is one line on stderr, whatever bytes a value or path in it had (the values in a
// message are cut already; this bounds the whole).
std::string oneLine(const std::string& message) { return grainlab::io::printable(message, 600); }

// An option's value may not be empty: "--out ''" used to mean "not given" (the config's output.dir),
// "--scheduler ''" a local sweep. Refused with the option's name.
const CLI::Validator kNonEmpty(
    [](std::string& value) {
      return value.empty() ? std::string("an empty value is not allowed (leave the option out instead)") : std::string();
    },
    "NON-EMPTY");
// Thread counts: the same range as solver.threads.
const CLI::Validator kThreadRange = CLI::Range(1, grainlab::cli::kMaxThreads);

}  // namespace

int main(int argc, char** argv) {
  using namespace grainlab;
  CLI::App app{"grainlab — DEM engine and virtual soil laboratory (triaxial tests on virtual sand)"};
  app.set_version_flag("--version", std::string("grainlab ") + GRAINLAB_VERSION);
  app.require_subcommand(1);

  cli::RunOptions run;
  auto* runCmd = app.add_subcommand("run", "Run a laboratory test from a TOML config or preset:NAME");
  runCmd->add_option("config", run.config, "CONFIG.toml or preset:NAME")->check(kNonEmpty)->required();
  runCmd->add_option("--out", run.outDir, "results folder (overrides output.dir)")->check(kNonEmpty);
  runCmd->add_option("--set", run.overrides, "override a config key: KEY=VALUE (TOML value)")
      ->allow_extra_args(false);
  runCmd->add_option("--threads", run.threads, "OpenMP threads (overrides solver.threads); fewer when other processes keep the cores busy (a warning says so; GRAINLAB_KEEP_THREADS=1 keeps them)")
      ->check(CLI::PositiveNumber);
  runCmd->add_flag("--quiet", run.quiet, "no progress output");

  app.add_subcommand("presets", "List the shipped presets");

  cli::ResumeOptions resume;
  auto* resumeCmd = app.add_subcommand("resume", "Continue an interrupted run from its checkpoint");
  resumeCmd->add_option("dir", resume.dir, "results folder of the run")->check(kNonEmpty)->required();
  resumeCmd->add_flag("--quiet", resume.quiet, "no progress output");
  resumeCmd->add_flag("--allow-older-version", resume.allowOlderVersion,
                      "accept a checkpoint written by an older grainlab (same checkpoint format)");

  cli::SweepOptions sweep;
  auto* sweepCmd = app.add_subcommand("sweep", "Run a grid of overrides in parallel processes and compare them");
  sweepCmd->add_option("config", sweep.config, "CONFIG.toml or preset:NAME")->check(kNonEmpty)->required();
  sweepCmd->add_option("--vary", sweep.vary, "KEY=V1,V2,... (repeat for a grid)")->allow_extra_args(false);
  sweepCmd->add_option("--seeds", sweep.seeds, "replicate seeds per case: sample.seed, +1, ..., +N-1; adds sweep-stats.csv/.md")
      ->capture_default_str();
  sweepCmd->add_option("--set", sweep.overrides, "override applied to every case")->allow_extra_args(false);
  sweepCmd->add_option("--jobs", sweep.jobs, "cases run at once")->capture_default_str();
  sweepCmd->add_option("--threads", sweep.threads, "threads per case (default: cores / jobs when jobs > 1, else solver.threads)")
      ->check(kThreadRange);
  sweepCmd->add_option("--out", sweep.outDir, "folder of the sweep (default runs/sweep)")->check(kNonEmpty);
  sweepCmd->add_flag("--quiet", sweep.quiet, "no progress output");
  auto* schedulerOpt =
      sweepCmd->add_option("--scheduler", sweep.scheduler, "run the cases on this Dask scheduler (tcp://HOST:PORT)")->check(kNonEmpty);
  sweepCmd->add_flag("--shared-out", sweep.sharedOut, "with --scheduler: every worker sees --out at the same path")
      ->needs(schedulerOpt);

  cli::CalibrateOptions calibrate;
  auto* calibrateCmd = app.add_subcommand("calibrate", "Fit micro-parameters to laboratory values and curves");
  calibrateCmd->add_option("config", calibrate.config, "CONFIG.toml or preset:NAME")->check(kNonEmpty)->required();
  calibrateCmd->add_option("--target", calibrate.target, "TARGET.toml: parameters, targets, optimiser")->check(kNonEmpty)->required();
  calibrateCmd->add_option("--jobs", calibrate.jobs, "runs at once (default: [execution] jobs, else the cores)")
      ->check(CLI::PositiveNumber);
  calibrateCmd->add_option("--scheduler", calibrate.scheduler, "run on this Dask scheduler (tcp://HOST:PORT)")->check(kNonEmpty);
  calibrateCmd->add_option("--out", calibrate.outDir, "calibration folder (default runs/calibration); rerun to resume")->check(kNonEmpty);
  calibrateCmd->add_flag("--quiet", calibrate.quiet, "no progress output");

  cli::RunOptions check;
  auto* checkCmd = app.add_subcommand("check", "Validate a config and print it with every default filled in");
  checkCmd->add_option("config", check.config, "CONFIG.toml or preset:NAME")->check(kNonEmpty)->required();
  checkCmd->add_option("--set", check.overrides, "override a config key: KEY=VALUE (TOML value)")
      ->allow_extra_args(false);

  cli::BenchOptions bench;
  auto* benchCmd = app.add_subcommand("bench", "Time a named scene (particle-steps per second)");
  benchCmd->add_option("scene", bench.scene, "scene name (triaxial-iso)")->capture_default_str();
  benchCmd->add_option("--particles", bench.particles, "number of particles")->capture_default_str();
  benchCmd->add_option("--steps", bench.steps, "timed steps")->capture_default_str();
  benchCmd->add_option("--threads", bench.threads, "OpenMP threads")->capture_default_str()->check(kThreadRange);
  benchCmd->add_flag("--json", bench.json, "print one JSON object");
  benchCmd->add_option("--packing", bench.packing,
                       "time this packing file (walls or periodic cell, spheres or ellipsoids) held at the "
                       "config's confining pressure, instead of a scene")->check(kNonEmpty);
  benchCmd->add_option("--config", bench.config,
                       "with --packing: CONFIG.toml or preset:NAME giving the contact law, damping and pressure "
                       "(default: the [W] law at 100 kPa)")->check(kNonEmpty);

  cli::AnalyseOptions analyse;
  auto* analyseCmd = app.add_subcommand("analyse", "Micromechanics of a finished run, from its snapshots (DIR/micro)");
  analyseCmd->add_option("dir", analyse.dir, "results folder of the run")->check(kNonEmpty)->required();
  analyseCmd->add_option("--classes", analyse.classDivisions, "N: 24*N^2 orientation classes")->capture_default_str();
  analyseCmd->add_flag("--fourth-order", analyse.fourthOrder, "also the fourth-order anisotropies");
  analyseCmd->add_flag("--no-plots", [&](std::int64_t) { analyse.plots = false; }, "skip the pictures");
  analyseCmd->add_flag("--quiet", analyse.quiet, "no table on stdout");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::fprintf(stderr, "grainlab: %s (grainlab --help lists the options)\n", io::printable(e.what(), 300).c_str());
    return 2;
  }

  try {
    cli::applySimdEnvironment();
    if (app.got_subcommand("presets")) {
      for (const auto& p : io::presets()) fmt::print("{:<22} {}\n", p.name, p.description);
      return 0;
    }
    if (app.got_subcommand("bench")) return cli::runBench(bench);
    if (app.got_subcommand("analyse")) return cli::runAnalyse(analyse);
    if (app.got_subcommand("sweep")) return cli::runSweep(sweep);
    if (app.got_subcommand("calibrate")) return cli::runCalibrate(calibrate);
    if (app.got_subcommand("check")) return cli::checkConfig(check);
    if (app.got_subcommand("resume")) return cli::resumeLab(resume);
    return cli::runLab(run);
  } catch (const InputError& e) {
    std::fprintf(stderr, "grainlab: %s\n", oneLine(e.what()).c_str());
    return 2;
  } catch (const SimulationError& e) {
    std::fprintf(stderr, "grainlab: run failed: %s\n", oneLine(e.what()).c_str());
    return 1;
  } catch (const io::FileError& e) {
    std::fprintf(stderr, "grainlab: %s\n", oneLine(e.what()).c_str());
    return 1;
  } catch (const std::filesystem::filesystem_error& e) {
    std::fprintf(stderr, "grainlab: %s\n",
                 oneLine(fmt::format("{} {}: {}", e.what(), io::quotedPath(e.path1()), e.code().message())).c_str());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "grainlab: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "grainlab: error: %s\n", oneLine(e.what()).c_str());
    return 1;
  }
}

#pragma once
// The subcommands of the grainlab executable.
#include <optional>
#include <string>
#include <vector>

#include "core/simulation.hpp"
#include "lab/protocols.hpp"
#include "lab/run_config.hpp"

namespace grainlab::cli {

// Reads and validates every file a config names (grading list, sphericity CSV, packing) as a run
// would use it, before anything is written; returns the packed sample of sample.packing. Throws
// InputError naming the key, the file and the line.
std::optional<Simulation> loadInputFiles(const lab::RunConfig& config);

struct RunOptions {
  std::string config;
  std::string outDir;
  std::vector<std::string> overrides;
  int threads = 0;  // 0: from the config
  bool quiet = false;
};
// `grainlab run`: returns the exit code; throws InputError / SimulationError.
int runLab(const RunOptions& options);
// The same run of an already resolved config (the Python module's grainlab.run): options.config is
// only the summary's config_source. `observer` also sees every progress report (and may throw
// RunInterrupted to stop the run between steps).
int runResolved(const lab::RunConfig& config, const RunOptions& options, const lab::ProgressFn& observer);
struct ResumeOptions {
  std::string dir;
  bool quiet = false;
  bool allowOlderVersion = false;  // accept a checkpoint of an older grainlab with the same format
};
// `grainlab resume DIR`: continues an interrupted run from its checkpoint.
int resumeLab(const ResumeOptions& options);

// `grainlab check`: validates and prints the resolved config (TOML) on stdout.
int checkConfig(const RunOptions& options);

struct SweepOptions {
  std::string config;
  std::vector<std::string> vary;       // KEY=V1,V2,...
  std::vector<std::string> overrides;  // --set applied to every case
  std::string outDir;
  int jobs = 2;
  int seeds = 1;    // replicate seeds per case (sample.seed, +1, ...); > 1 adds sweep-stats.csv/.md
  int threads = 0;  // per case; 0: from the config
  bool quiet = false;
  std::string scheduler;   // tcp://HOST:PORT: cases run on that Dask cluster (sweep_dask.hpp)
  bool sharedOut = false;  // with scheduler: workers write into the folder directly (a shared path)
};
// `grainlab sweep`: exit 0 when every case completed, 1 when any failed.
int runSweep(const SweepOptions& options);

struct CalibrateOptions {
  std::string config;
  std::string target;     // TARGET.toml (docs/calibration.md)
  std::string outDir;     // the calibration folder (default runs/calibration)
  std::string scheduler;  // tcp://HOST:PORT: runs on that Dask cluster
  int jobs = 0;           // runs at once (0: the target's [execution] jobs, else the cores)
  bool quiet = false;
};
// `grainlab calibrate`: validates, then becomes the Python driver (tools/calibrate.py) whose exit
// code is the command's.
int runCalibrate(const CalibrateOptions& options);

struct BenchOptions {
  std::string scene = "triaxial-iso";
  int particles = 2000;
  long steps = 2000;
  int threads = 1;
  bool json = false;
  std::string packing;  // time this packing instead of a scene
  std::string config;   // the contact law, damping and pressure for --packing (default: the [W] law)
};
int runBench(const BenchOptions& options);

struct AnalyseOptions {
  std::string dir;
  int classDivisions = 4;    // N: 24·N² orientation classes
  bool fourthOrder = false;  // also the fourth-order anisotropies
  bool plots = true;
  bool quiet = false;
};
// `grainlab analyse DIR`: the micromechanics of a run recomputed from DIR/micro/ snapshots.
int runAnalyse(const AnalyseOptions& options);

}  // namespace grainlab::cli

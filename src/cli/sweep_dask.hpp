#pragma once
// Sweep cases on a Dask distributed cluster (docs/scale-out.md): each case is one `grainlab run` on
// a worker, started by tools/dask_runner.py.
#include <filesystem>
#include <string>
#include <vector>

#include "cli/commands.hpp"

namespace grainlab::cli {

// Throws InputError unless `address` is a scheduler address tcp://HOST:PORT (or tls://); `where`
// names the option or key in the message.
void checkSchedulerAddress(const std::string& address, const std::string& where);

struct DaskCase {
  std::string name;               // the case's folder under the sweep's folder
  std::vector<std::string> sets;  // its --set KEY=VALUE overrides, in order
};

struct DaskCaseResult {
  bool ran = false;   // the runner reported it (false: not run, e.g. lost with the scheduler)
  int exitCode = -1;  // of its `grainlab run`
  int attempts = 0;   // > 1 when a worker was lost mid-case and the case ran again elsewhere
  std::string workers;  // the workers of its attempts, in order ("a then b")
};

struct DaskOutcome {
  std::vector<DaskCaseResult> cases;  // in the order given
  std::string error;                  // one line: why some cases were not run (empty: all ran)
};

// Runs the cases on the cluster of opt.scheduler (threads per case: `threads`, or 0 for one thread:
// each of a worker's task slots is one core); their folders end up in `out` as the local sweep's do. Blocks
// until every case is done or the cluster is lost (a scheduler that cannot be reached or dies, a
// runner stopped by a signal): the cases finished until then are reported, the others not, and
// `error` says why. Throws std::runtime_error only when the runner is not installed.
DaskOutcome runCasesOnDask(const SweepOptions& opt, const std::string& executable,
                                           const std::filesystem::path& out, const std::vector<DaskCase>& cases,
                                           int threads);

}  // namespace grainlab::cli

#pragma once
// How many OpenMP threads a run can use without oversubscribing the cores (issue 15, "a busy
// machine"): OpenMP's barriers make a run on more threads than free cores 10-40x slower, while
// results do not depend on the thread count.
#include <optional>
#include <string>

namespace grainlab::cli {

// Runnable tasks of other processes right now: the median of a few samples of /proc/stat's
// procs_running (which counts this process' own running thread, subtracted). Nothing where
// /proc/stat cannot be read.
std::optional<int> otherRunnableTasks();

// Cores this process may run on (its CPU affinity mask).
int usableCores();

struct ThreadChoice {
  int threads = 1;        // what the run uses
  std::string warning;    // empty, or one line for stderr
};

// `requested` threads, or as many as the free cores when other processes keep cores busy; with
// adapt = false, or the environment variable GRAINLAB_KEEP_THREADS=1, `requested` is kept and
// only the warning says so.
ThreadChoice chooseThreads(int requested, bool adapt = true);

}  // namespace grainlab::cli

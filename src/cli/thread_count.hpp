#pragma once
// How many OpenMP threads a run can use without oversubscribing the cores (issue 15, "a busy
// machine"): OpenMP's barriers make a run on more threads than free cores 10-40x slower, while
// results do not depend on the thread count.
#include <optional>
#include <string>

namespace grainlab::cli {

// The most OpenMP threads any command accepts (solver.threads, --threads of run, sweep and bench).
inline constexpr int kMaxThreads = 1024;

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
// In a process forked after OpenMP teams of more than one thread had run (Python's multiprocessing
// with the "fork" start method), also 1 thread with a warning: libgomp's threads do not survive
// fork, and a team of two or more in the child waits forever for them (a team of one works).
ThreadChoice chooseThreads(int requested, bool adapt = true);

// Sets OpenMP's thread count for the next parallel regions and remembers whether teams of more than
// one thread ran in this process (what a fork must know). Every omp_set_num_threads of the program
// and the Python module goes through here.
void setOpenMPThreads(int threads);
// Whether this process is a child forked after teams of more than one thread had run.
bool forkedAfterOpenMPTeams();
// The warning chooseThreads gives in such a child (for the Python module's warnings.warn).
std::string forkedThreadsWarning(int requested);

// Applies the environment variable GRAINLAB_SIMD (core/kernels/integrate_simd.hpp): which
// vector target the kernels use ("best" when unset; results are bit-identical for every target).
// An InputError names the value and the names allowed on this machine.
void applySimdEnvironment();

}  // namespace grainlab::cli

#include "cli/thread_count.hpp"

#include <omp.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/kernels/integrate_simd.hpp"
#include "io/input_file.hpp"

namespace grainlab::cli {

namespace {

std::optional<int> procsRunning() {
  std::ifstream in("/proc/stat");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("procs_running ", 0) == 0) {
      std::istringstream s(line.substr(14));
      int n = 0;
      if (s >> n && n >= 0) return n;
      return std::nullopt;
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<int> otherRunnableTasks() {
  std::vector<int> samples;
  for (int i = 0; i < 5; ++i) {
    if (i > 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const std::optional<int> n = procsRunning();
    if (!n) return std::nullopt;
    samples.push_back(std::max(0, *n - 1));  // this process' reading thread is running
  }
  std::sort(samples.begin(), samples.end());
  return samples[samples.size() / 2];
}

int usableCores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

namespace {

std::atomic<bool> teamsStarted{false};
std::atomic<bool> forkedAfterTeams{false};

// In the child of a fork (async-signal-safe: only atomics).
void afterForkInChild() {
  if (teamsStarted.load(std::memory_order_relaxed)) forkedAfterTeams.store(true, std::memory_order_relaxed);
}

const bool kForkHandlerRegistered = [] { return ::pthread_atfork(nullptr, nullptr, &afterForkInChild) == 0; }();

}  // namespace

void setOpenMPThreads(int threads) {
  if (forkedAfterTeams.load(std::memory_order_relaxed)) threads = 1;
  if (threads > 1) teamsStarted.store(true, std::memory_order_relaxed);
  omp_set_num_threads(std::max(1, threads));
}

bool forkedAfterOpenMPTeams() {
  (void)kForkHandlerRegistered;
  return forkedAfterTeams.load(std::memory_order_relaxed);
}

std::string forkedThreadsWarning(int requested) {
  return fmt::format(
      "grainlab: warning: this process was forked after OpenMP threads had run (libgomp's threads do not survive "
      "fork): running on 1 thread instead of {}; start processes with multiprocessing's \"spawn\" or "
      "\"forkserver\" method to use more (results do not depend on the thread count)",
      requested);
}

ThreadChoice chooseThreads(int requested, bool adapt) {
  ThreadChoice c;
  c.threads = requested;
  if (requested > 1 && forkedAfterOpenMPTeams()) {
    c.threads = 1;
    c.warning = forkedThreadsWarning(requested);
    return c;
  }
  if (requested <= 1) return c;
  const std::optional<int> others = otherRunnableTasks();
  if (!others) return c;
  const int cores = usableCores();
  const int free = std::max(1, cores - *others);
  if (requested <= free) return c;
  const char* keep = std::getenv("GRAINLAB_KEEP_THREADS");
  const bool keepRequested = !adapt || (keep && std::string(keep) == "1");
  if (!keepRequested) c.threads = free;
  c.warning = fmt::format(
      "grainlab: warning: {} other running task{} on {} core{}: {} threads would oversubscribe them (OpenMP then "
      "runs many times slower); {} (results do not depend on the thread count{})",
      *others, *others == 1 ? "" : "s", cores, cores == 1 ? "" : "s", requested,
      keepRequested ? fmt::format("keeping {} threads as asked", requested)
                    : fmt::format("using {} thread{}", free, free == 1 ? "" : "s"),
      keepRequested ? (std::getenv("OMP_WAIT_POLICY") ? ""
                                                      : "; OMP_WAIT_POLICY=PASSIVE makes the kept threads wait "
                                                        "without spinning, which is much faster on busy cores")
                    : "; GRAINLAB_KEEP_THREADS=1 keeps the requested count");
  return c;
}

void applySimdEnvironment() {
  const char* text = std::getenv(kernels::SimdChoice::kEnvironment);
  if (text == nullptr) return;
  try {
    kernels::selectSimdTarget(text);
  } catch (const std::invalid_argument&) {
    std::string allowed;
    for (const std::string& n : kernels::simdTargetNames()) allowed += (allowed.empty() ? "" : ", ") + n;
    throw InputError(std::string("environment error: ") + kernels::SimdChoice::kEnvironment + " = \"" +
                     io::printable(text) + "\" is not a vector target of this program and CPU; allowed: " + allowed);
  }
}

}  // namespace grainlab::cli

#pragma once
// Child processes (plots, sweep cases) started from an argument vector: posix_spawn with the
// program's absolute path, never a shell, so no byte of a path or value is ever interpreted.
#include <sys/types.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace grainlab::io {

// Where a child's standard output and error go.
struct ChildOutput {
  enum class Kind { Inherit, Discard, File };
  Kind kind = Kind::Inherit;
  std::filesystem::path file;  // Kind::File: both streams, truncated first

  static ChildOutput inherit() { return {}; }
  static ChildOutput discard() { return {Kind::Discard, {}}; }
  static ChildOutput toFile(std::filesystem::path f) { return {Kind::File, std::move(f)}; }
};

// Starts argv[0] (a path; no PATH search) with exactly these arguments; throws FileError naming the
// program and the system's reason when it cannot be started. dieWithParent: the child is killed
// (SIGKILL, prctl PR_SET_PDEATHSIG) when this process ends, however it ends, so a killed sweep leaves
// no case writing into its folder; such a child is started with fork + exec (posix_spawn cannot
// run code in the child), with only async-signal-safe calls between the two.
// `environment`: "NAME=value" entries that replace (or add to) this process's environment in the child.
// `cpus` (dieWithParent only): the CPUs the child may run on, set before it starts (a bound parent's
// mask is otherwise inherited, and libgomp drops every place outside it).
pid_t startProcess(const std::vector<std::string>& argv, const ChildOutput& output = {}, bool dieWithParent = false,
                   const std::vector<std::string>& environment = {}, const std::vector<int>& cpus = {});
// The exit code of a finished child, or 128 + the signal number that ended it (as a shell reports).
int exitCodeOf(int waitStatus);
// Waits for one child; returns its exit code as exitCodeOf.
int waitProcess(pid_t pid);
// Waits for any child; returns its pid and exit code.
std::pair<pid_t, int> waitAnyProcess();
// startProcess + waitProcess.
int runProcess(const std::vector<std::string>& argv, const ChildOutput& output = {});

// The CPUs this process may run on, in increasing order ({0} when unknown): sched_getaffinity, or
// under OMP_PROC_BIND the CPUs of libgomp's places (the mask before libgomp bound this process).
std::vector<int> allowedCpus();
// OMP_PLACES for the job in slot `slot` of concurrent jobs of `threads` threads each on `cpus`: one
// place per thread, "{c}" for consecutive CPUs of the slot's own block (wrapping round when the jobs
// need more CPUs than there are). With OMP_PROC_BIND set, libgomp binds every process's first
// thread to the first place, so without this every one-thread job of a sweep runs on the same core.
std::string ompPlacesFor(std::size_t slot, int threads, const std::vector<int>& cpus);
// The CPUs of that block, in the same order.
std::vector<int> cpusFor(std::size_t slot, int threads, const std::vector<int>& cpus);
// Whether OMP_PROC_BIND is set to something other than false (so places decide where threads run).
bool ompBindingRequested();

// While one is alive, SIGTERM, SIGINT and SIGHUP do not end this process: each is passed on to the
// children registered with track() (which end by it), and stopSignal() says which came, so that the
// command can wait for its children, write what finished and exit 128 + the signal.
class StopForwarding {
 public:
  StopForwarding();
  ~StopForwarding();
  StopForwarding(const StopForwarding&) = delete;
  StopForwarding& operator=(const StopForwarding&) = delete;
  // Registers a started child (signalled at once when a stop signal came already); at most 1024 at once.
  static void track(pid_t pid);
  static void untrack(pid_t pid);
  static int stopSignal();  // 0, or the signal that came
};

}  // namespace grainlab::io

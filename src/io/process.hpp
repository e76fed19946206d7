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
pid_t startProcess(const std::vector<std::string>& argv, const ChildOutput& output = {}, bool dieWithParent = false);
// The exit code of a finished child, or 128 + the signal number that ended it (as a shell reports).
int exitCodeOf(int waitStatus);
// Waits for one child; returns its exit code as exitCodeOf.
int waitProcess(pid_t pid);
// Waits for any child; returns its pid and exit code.
std::pair<pid_t, int> waitAnyProcess();
// startProcess + waitProcess.
int runProcess(const std::vector<std::string>& argv, const ChildOutput& output = {});

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

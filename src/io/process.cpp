#include "io/process.hpp"

#include <fcntl.h>
#include <omp.h>
#include <fmt/format.h>
#include <signal.h>
#include <spawn.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <algorithm>

#include "io/input_file.hpp"

extern char** environ;

namespace grainlab::io {

namespace {

// posix_spawn file actions, destroyed on every path out.
struct FileActions {
  posix_spawn_file_actions_t actions;
  FileActions() { posix_spawn_file_actions_init(&actions); }
  ~FileActions() { posix_spawn_file_actions_destroy(&actions); }
};

FileError startError(const std::vector<std::string>& args, const ChildOutput& output, int err) {
  return FileError(output.kind == ChildOutput::Kind::File
                       ? fmt::format("cannot start {} with its output in {}: {}", quotedPath(args[0]),
                                     quotedPath(output.file), std::strerror(err))
                       : fileErrorMessage("cannot start", args[0], err));
}

// fork + exec with PR_SET_PDEATHSIG in the child. Between fork and exec only async-signal-safe
// calls (the process may have other threads); the reason of a failed start comes back through a
// close-on-exec pipe (nothing read: exec succeeded).
pid_t startTiedProcess(std::vector<std::string>& args, std::vector<char*>& pointers, const ChildOutput& output,
                       char** envp, const cpu_set_t* cpus) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw FileError(fileErrorMessage("cannot start", args[0], errno));
  const pid_t parent = ::getpid();
  const char* file = output.kind == ChildOutput::Kind::File ? output.file.c_str() : "/dev/null";
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int err = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw FileError(fileErrorMessage("cannot start", args[0], err));
  }
  if (pid == 0) {
    int err = 0;
    // A stop signal here ends this child alone (the parent's handler would pass it on to siblings).
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    for (const int sig : {SIGTERM, SIGINT, SIGHUP}) ::sigaction(sig, &dfl, nullptr);
    // The parent may have ended before prctl: then this child is an orphan already and stops.
    if (::prctl(PR_SET_PDEATHSIG, SIGKILL) != 0) err = errno;
    if (!err && ::getppid() != parent) ::_exit(127);
    if (!err && cpus && ::sched_setaffinity(0, sizeof *cpus, cpus) != 0) err = errno;
    if (!err && output.kind != ChildOutput::Kind::Inherit) {
      const int flags = output.kind == ChildOutput::Kind::File ? O_WRONLY | O_CREAT | O_TRUNC : O_WRONLY;
      const int fd = ::open(file, flags, 0644);
      if (fd < 0 || ::dup2(fd, STDOUT_FILENO) < 0 || ::dup2(fd, STDERR_FILENO) < 0) err = errno;
      if (fd > STDERR_FILENO) ::close(fd);
    }
    if (!err) {
      // The handlers of StopForwarding are reset by exec; the mask is not.
      sigset_t none;
      sigemptyset(&none);
      ::sigprocmask(SIG_SETMASK, &none, nullptr);
      ::execve(args[0].c_str(), pointers.data(), envp);
      err = errno;
    }
    [[maybe_unused]] const auto n = ::write(fds[1], &err, sizeof err);
    ::_exit(127);
  }
  ::close(fds[1]);
  int err = 0;
  ssize_t n;
  while ((n = ::read(fds[0], &err, sizeof err)) < 0 && errno == EINTR) {
  }
  ::close(fds[0]);
  if (n > 0) {
    int status;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    throw startError(args, output, err);
  }
  return pid;
}

}  // namespace

pid_t startProcess(const std::vector<std::string>& argv, const ChildOutput& output, bool dieWithParent,
                   const std::vector<std::string>& environment, const std::vector<int>& cpus) {
  if (argv.empty()) throw FileError("startProcess: empty argument vector");
  std::vector<std::string> args = argv;  // posix_spawn takes char* const[]
  std::vector<char*> pointers;
  for (auto& a : args) pointers.push_back(a.data());
  pointers.push_back(nullptr);
  // The child's environment: ours, with the given NAME=value entries in place of their names'.
  std::vector<std::string> env = environment;
  std::vector<char*> envPointers;
  char** envp = environ;
  if (!env.empty()) {
    auto nameOf = [](std::string_view e) { return e.substr(0, e.find('=')); };
    for (char** e = environ; e && *e; ++e) {
      bool replaced = false;
      for (const auto& o : env) replaced = replaced || nameOf(o) == nameOf(*e);
      if (!replaced) envPointers.push_back(*e);
    }
    for (auto& o : env) envPointers.push_back(o.data());
    envPointers.push_back(nullptr);
    envp = envPointers.data();
  }
  cpu_set_t cpuSet;
  CPU_ZERO(&cpuSet);
  for (int c : cpus)
    if (c >= 0 && c < CPU_SETSIZE) CPU_SET(c, &cpuSet);
  if (dieWithParent) return startTiedProcess(args, pointers, output, envp, cpus.empty() ? nullptr : &cpuSet);
  if (!cpus.empty()) throw FileError("startProcess: a CPU set needs dieWithParent (fork and exec)");
  FileActions fa;
  if (output.kind == ChildOutput::Kind::Discard) {
    posix_spawn_file_actions_addopen(&fa.actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_adddup2(&fa.actions, STDOUT_FILENO, STDERR_FILENO);
  } else if (output.kind == ChildOutput::Kind::File) {
    posix_spawn_file_actions_addopen(&fa.actions, STDOUT_FILENO, output.file.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_adddup2(&fa.actions, STDOUT_FILENO, STDERR_FILENO);
  }
  pid_t pid = 0;
  const int rc = ::posix_spawn(&pid, args[0].c_str(), &fa.actions, nullptr, pointers.data(), envp);
  // The error may come from the program or from opening the log (posix_spawn reports either).
  if (rc != 0) throw startError(args, output, rc);
  return pid;
}

std::vector<int> allowedCpus() {
  std::vector<int> out;
  // With OMP_PROC_BIND set, libgomp has already bound this process's own thread to its first place
  // (at load time), so the affinity mask says one CPU; its place list still holds every CPU of the
  // mask the process started with.
  if (ompBindingRequested()) {
    for (int p = 0; p < omp_get_num_places(); ++p) {
      std::vector<int> ids(static_cast<std::size_t>(omp_get_place_num_procs(p)));
      omp_get_place_proc_ids(p, ids.data());
      out.insert(out.end(), ids.begin(), ids.end());
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    if (!out.empty()) return out;
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  if (::sched_getaffinity(0, sizeof set, &set) == 0)
    for (int c = 0; c < CPU_SETSIZE; ++c)
      if (CPU_ISSET(c, &set)) out.push_back(c);
  if (out.empty()) out.push_back(0);
  return out;
}

std::vector<int> cpusFor(std::size_t slot, int threads, const std::vector<int>& cpus) {
  const std::size_t t = static_cast<std::size_t>(std::max(threads, 1));
  std::vector<int> out;
  for (std::size_t k = 0; k < t; ++k) out.push_back(cpus.empty() ? 0 : cpus[(slot * t + k) % cpus.size()]);
  return out;
}

std::string ompPlacesFor(std::size_t slot, int threads, const std::vector<int>& cpus) {
  std::string places;
  for (int cpu : cpusFor(slot, threads, cpus)) places += (places.empty() ? "{" : ",{") + std::to_string(cpu) + "}";
  return places;
}

bool ompBindingRequested() {
  const char* v = std::getenv("OMP_PROC_BIND");
  if (!v || !*v) return false;
  std::string s(v);
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s != "false";
}

int exitCodeOf(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return 1;
}

int waitProcess(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw FileError(fileErrorMessage("cannot wait for process", std::to_string(pid), errno));
  return exitCodeOf(status);
}

std::pair<pid_t, int> waitAnyProcess() {
  int status = 0;
  pid_t pid;
  while ((pid = ::waitpid(-1, &status, 0)) < 0)
    if (errno != EINTR) throw FileError(fileErrorMessage("cannot wait for child processes", "", errno));
  return {pid, exitCodeOf(status)};
}

int runProcess(const std::vector<std::string>& argv, const ChildOutput& output) {
  return waitProcess(startProcess(argv, output));
}

namespace {

constexpr std::size_t kTrackedChildren = 1024;
std::atomic<int> gStopSignal{0};
std::array<std::atomic<pid_t>, kTrackedChildren> gTracked{};
constexpr int kForwarded[] = {SIGTERM, SIGINT, SIGHUP};
struct sigaction gPrevious[3];
static_assert(std::atomic<pid_t>::is_always_lock_free && std::atomic<int>::is_always_lock_free);

extern "C" void forwardStop(int sig) {
  gStopSignal.store(sig);
  for (auto& slot : gTracked)
    if (const pid_t pid = slot.load(); pid > 0) ::kill(pid, sig);
}

}  // namespace

StopForwarding::StopForwarding() {
  gStopSignal.store(0);
  struct sigaction sa {};
  sa.sa_handler = forwardStop;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  for (std::size_t i = 0; i < 3; ++i) ::sigaction(kForwarded[i], &sa, &gPrevious[i]);
}

StopForwarding::~StopForwarding() {
  for (std::size_t i = 0; i < 3; ++i) ::sigaction(kForwarded[i], &gPrevious[i], nullptr);
}

void StopForwarding::track(pid_t pid) {
  for (auto& slot : gTracked) {
    pid_t empty = 0;
    if (slot.compare_exchange_strong(empty, pid)) {
      // A signal that came before the slot was filled did not reach this child.
      if (const int sig = gStopSignal.load()) ::kill(pid, sig);
      return;
    }
  }
  ::kill(pid, SIGKILL);
  throw FileError(fmt::format("more than {} child processes at once", kTrackedChildren));
}

void StopForwarding::untrack(pid_t pid) {
  for (auto& slot : gTracked) {
    pid_t p = pid;
    if (slot.compare_exchange_strong(p, 0)) return;
  }
}

int StopForwarding::stopSignal() { return gStopSignal.load(); }

}  // namespace grainlab::io

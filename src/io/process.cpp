#include "io/process.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

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

}  // namespace

pid_t startProcess(const std::vector<std::string>& argv, const ChildOutput& output) {
  if (argv.empty()) throw FileError("startProcess: empty argument vector");
  std::vector<std::string> args = argv;  // posix_spawn takes char* const[]
  std::vector<char*> pointers;
  for (auto& a : args) pointers.push_back(a.data());
  pointers.push_back(nullptr);
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
  const int rc = ::posix_spawn(&pid, args[0].c_str(), &fa.actions, nullptr, pointers.data(), environ);
  // The error may come from the program or from opening the log (posix_spawn reports either).
  if (rc != 0)
    throw FileError(output.kind == ChildOutput::Kind::File
                        ? fmt::format("cannot start {} with its output in {}: {}", quotedPath(args[0]),
                                      quotedPath(output.file), std::strerror(rc))
                        : fileErrorMessage("cannot start", args[0], rc));
  return pid;
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

}  // namespace grainlab::io

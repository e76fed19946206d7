#include "io/run_folder.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <algorithm>
#include <cstdio>
#include <set>
#include <sstream>
#include <system_error>

#include "core/errors.hpp"
#include "io/input_file.hpp"
#include "io/results.hpp"

namespace grainlab::io {

namespace fs = std::filesystem;

namespace {

// The absolute folder a requested path names ("out/", "out/." and "out" are the same folder).
fs::path normalisedFolder(const fs::path& requested) {
  std::error_code ec;
  fs::path p = fs::absolute(requested, ec);
  if (ec) throw FileError(fileErrorMessage("cannot resolve the results folder", requested, ec.value()));
  p = p.lexically_normal();
  while (!p.has_filename() && p.has_relative_path()) p = p.parent_path();
  if (!p.has_relative_path())
    throw InputError(fmt::format("output.dir = {}: must name a folder below the file-system root", quotedPath(requested)));
  if (fs::is_symlink(p, ec)) {
    const fs::path resolved = fs::canonical(p, ec);
    if (ec) throw FileError(fileErrorMessage("cannot follow the symbolic link", p, ec.value()));
    return resolved;
  }
  return p;
}

bool isEmptyFolder(const fs::path& dir) {
  std::error_code ec;
  const bool empty = fs::is_empty(dir, ec);
  if (ec) throw FileError(fileErrorMessage("cannot read the folder", dir, ec.value()));
  return empty;
}

void removeAll(const fs::path& p) {
  std::error_code ec;
  fs::remove_all(p, ec);
  if (ec) throw FileError(fileErrorMessage("cannot remove", p, ec.value()));
}

void makeFolder(const fs::path& dir) {
  if (dir.has_parent_path()) createDirectories(dir.parent_path());
  if (::mkdir(dir.c_str(), 0777) != 0) throw FileError(fileErrorMessage("cannot create the folder", dir, errno));
}

bool holdsResults(const fs::path& dir) {
  std::error_code ec;
  return fs::exists(dir / "config.resolved.toml", ec);
}

// What a run writes at the top of its folder, for folders without a manifest (written by an earlier
// grainlab, or by a run killed before it completed): these names, and temporary files NAME.tmpPID.
bool grainlabName(const std::string& name) {
  static const std::set<std::string> kNames{"config.resolved.toml", "summary.json", "timeseries.csv", "packing.txt",
                                            "checkpoint", "vtk", "micro", "plots", "stress_dilatancy.csv",
                                            RunFolder::kManifest};
  if (kNames.count(name)) return true;
  const auto tmp = name.rfind(".tmp");
  return tmp != std::string::npos && tmp + 4 < name.size() &&
         std::all_of(name.begin() + static_cast<long>(tmp) + 4, name.end(), [](char c) { return c >= '0' && c <= '9'; });
}

}  // namespace

std::vector<std::string> userEntries(const fs::path& dir) {
  std::set<std::string> listed;
  bool haveManifest = false;
  std::error_code ec;
  if (fs::is_regular_file(dir / RunFolder::kManifest, ec)) {
    try {
      std::istringstream in(readInputFile(dir / RunFolder::kManifest, "results manifest", kMaxConfigBytes));
      for (std::string line; std::getline(in, line);)
        if (!line.empty()) listed.insert(line);
      haveManifest = true;
    } catch (const InputError&) {
      // unreadable: fall back to grainlab's own names
    }
  }
  std::vector<std::string> out;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().native();
    const bool ours = haveManifest ? (listed.count(name) > 0 || name == RunFolder::kManifest) : grainlabName(name);
    if (!ours) out.push_back(name);
  }
  std::sort(out.begin(), out.end());
  return out;
}

void RunFolder::writeManifest(const fs::path& dir) {
  std::vector<std::string> names{kManifest};
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) names.push_back(entry.path().filename().native());
  if (ec) throw FileError(fileErrorMessage("cannot read the folder", dir, ec.value()));
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  std::string text;
  for (const auto& n : names)
    if (n.find('\n') == std::string::npos) text += n + "\n";
  writeFileAtomic(dir / kManifest, text);
}

int lockFolder(const fs::path& dir, bool closeOnExec) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | (closeOnExec ? O_CLOEXEC : 0));
  if (fd < 0) throw FileError(fileErrorMessage("cannot open the folder", dir, errno));
  if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return fd;
  const int err = errno;
  ::close(fd);
  if (err == EWOULDBLOCK) return -1;
  throw FileError(fileErrorMessage("cannot lock the folder", dir, err));
}

void RunFolder::lock() {
  const int fd = lockFolder(target_);
  if (fd < 0)
    throw InputError(fmt::format("output.dir = {}: another grainlab run or resume is writing into this folder now; "
                                 "allowed: one run per results folder at a time (give another --out, or wait)",
                                 quotedPath(target_)));
  lock_ = std::shared_ptr<int>(new int(fd), [](int* p) {
    ::close(*p);
    delete p;
  });
}

void RunFolder::keepUserFiles() const {
  // work_ now holds the earlier results (exchanged out of target_).
  std::error_code ec;
  for (const std::string& name : userEntries(work_)) {
    fs::path to = target_ / name;
    if (fs::symlink_status(to, ec).type() != fs::file_type::not_found) {
      to = target_ / (name + ".before-rerun");
      std::fprintf(stderr, "grainlab: warning: %s is also a name of the new results; the earlier file is kept as %s\n",
                   quotedPath(target_ / name).c_str(), quotedPath(to).c_str());
    }
    if (::rename((work_ / name).c_str(), to.c_str()) != 0)
      std::fprintf(stderr, "grainlab: warning: %s\n",
                   fileErrorMessage("cannot keep the file added to the earlier results", work_ / name, errno).c_str());
  }
}

fs::path RunFolder::stagingFolderOf(const fs::path& target) {
  return target.parent_path() / ("." + target.filename().native() + ".grainlab-new");
}

RunFolder RunFolder::forRun(const fs::path& requested) {
  RunFolder f;
  f.target_ = normalisedFolder(requested);
  f.work_ = f.target_;
  std::error_code ec;
  const fs::file_status st = fs::status(f.target_, ec);
  if (ec && ec != std::errc::no_such_file_or_directory)
    throw FileError(fileErrorMessage("cannot use the results folder", f.target_, ec.value()));
  if (!fs::exists(st)) {
    if (f.target_.has_parent_path()) createDirectories(f.target_.parent_path());
    if (::mkdir(f.target_.c_str(), 0777) == 0) {
      f.origin_ = Origin::Created;
      f.lock();  // a run that created the folder a moment ago may hold it already: then refused, nothing removed
      return f;
    }
    if (errno != EEXIST) throw FileError(fileErrorMessage("cannot create the folder", f.target_, errno));
    // Created by another process meanwhile: taken as an existing folder below.
  }
  if (!fs::is_directory(f.target_, ec)) throw FileError(fileErrorMessage("cannot use the results folder", f.target_, ENOTDIR));
  f.lock();
  // Refused here, before any work, rather than by the first write (and never bypassed by
  // replacing the folder through its writable parent).
  if (::access(f.target_.c_str(), W_OK | X_OK) != 0)
    throw FileError(fileErrorMessage("cannot write into the results folder", f.target_, errno));
  if (isEmptyFolder(f.target_)) {
    f.origin_ = Origin::WasEmpty;
    return f;
  }
  checkReplaceable(f.target_);
  f.work_ = stagingFolderOf(f.target_);
  f.origin_ = Origin::Staged;
  const fs::file_status old = fs::symlink_status(f.work_, ec);
  if (fs::exists(old)) {
    // What a killed earlier re-run left; a new run starts over.
    if (!fs::is_directory(old) || !(isEmptyFolder(f.work_) || holdsResults(f.work_)))
      throw InputError(fmt::format("output.dir = {}: {} is in the way (not a grainlab staging folder)",
                                   quotedPath(f.target_), quotedPath(f.work_)));
    removeAll(f.work_);
  }
  makeFolder(f.work_);
  return f;
}

void RunFolder::checkReplaceable(const fs::path& requested) {
  const fs::path target = normalisedFolder(requested);
  std::error_code ec;
  if (!fs::is_directory(target, ec) || fs::is_empty(target, ec) || holdsResults(target)) return;
  throw InputError(fmt::format(
      "output.dir = {}: the folder is not empty and holds no grainlab results (no config.resolved.toml); "
      "grainlab replaces only its own results: give a new or empty folder",
      quotedPath(target)));
}

RunFolder RunFolder::forResume(const fs::path& requested) {
  RunFolder f;
  f.target_ = normalisedFolder(requested);
  f.work_ = f.target_;
  f.origin_ = Origin::Resumed;
  std::error_code ec;
  if (fs::is_directory(f.target_, ec)) f.lock();
  const fs::path staging = stagingFolderOf(f.target_);
  // A killed re-run: its checkpoint, or results written but not yet made complete (plots pending).
  if (fs::is_directory(staging, ec) && holdsResults(staging) &&
      (fs::exists(staging / "checkpoint" / "state.bin", ec) || fs::exists(staging / "summary.json", ec)))
    f.work_ = staging;
  return f;
}

void RunFolder::commit() {
  if (!staged()) return;
  // One atomic step: the new results appear and the earlier ones move to the staging name.
  if (::renameat2(AT_FDCWD, work_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) == 0) {
    keepUserFiles();
    std::error_code ec;
    fs::remove_all(work_, ec);
    if (ec)
      std::fprintf(stderr, "grainlab: warning: %s\n",
                   fileErrorMessage("cannot remove the earlier results, moved to", work_, ec.value()).c_str());
    return;
  }
  const int err = errno;
  if (err == ENOENT) {  // the earlier folder is gone meanwhile
    if (::rename(work_.c_str(), target_.c_str()) != 0)
      throw FileError(fileErrorMessage("cannot move the results into", target_, errno));
    return;
  }
  if (err != EINVAL && err != ENOSYS) throw FileError(fileErrorMessage("cannot move the results into", target_, err));
  // A file system without RENAME_EXCHANGE: two renames, with the earlier results kept aside until
  // the new ones are in place.
  const fs::path aside = target_.parent_path() / ("." + target_.filename().native() + ".grainlab-old");
  removeAll(aside);
  if (::rename(target_.c_str(), aside.c_str()) != 0)
    throw FileError(fileErrorMessage("cannot move the earlier results aside to", aside, errno));
  if (::rename(work_.c_str(), target_.c_str()) != 0) {
    const int e = errno;
    ::rename(aside.c_str(), target_.c_str());
    throw FileError(fileErrorMessage("cannot move the results into", target_, e));
  }
  RunFolder old = *this;
  old.work_ = aside;
  old.keepUserFiles();
  removeAll(aside);
}

void RunFolder::discard() {
  std::error_code ec;
  switch (origin_) {
    case Origin::Resumed:
      if (!staged()) return;
      [[fallthrough]];
    case Origin::Staged:
    case Origin::Created:
      fs::remove_all(work_, ec);
      return;
    case Origin::WasEmpty:
      for (const auto& entry : fs::directory_iterator(work_, ec)) fs::remove_all(entry.path(), ec);
      return;
  }
}

}  // namespace grainlab::io

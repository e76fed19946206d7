#include "io/run_folder.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
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

}  // namespace

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
    makeFolder(f.target_);
    f.origin_ = Origin::Created;
    return f;
  }
  if (!fs::is_directory(st)) throw FileError(fileErrorMessage("cannot use the results folder", f.target_, ENOTDIR));
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
  const fs::path staging = stagingFolderOf(f.target_);
  std::error_code ec;
  if (fs::is_directory(staging, ec) && fs::exists(staging / "checkpoint" / "state.bin", ec) && holdsResults(staging))
    f.work_ = staging;
  return f;
}

void RunFolder::commit() {
  if (!staged()) return;
  // One atomic step: the new results appear and the earlier ones move to the staging name.
  if (::renameat2(AT_FDCWD, work_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) == 0) {
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

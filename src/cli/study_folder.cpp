#include "cli/study_folder.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

#include "core/errors.hpp"
#include "io/input_file.hpp"
#include "io/results.hpp"
#include "io/run_folder.hpp"

namespace grainlab::cli {

namespace fs = std::filesystem;

StudyFolder claimStudyFolder(const fs::path& requested, const std::string& option, const std::string& marker,
                             const std::string& what, bool keepLockAcrossExec) {
  StudyFolder f;
  f.dir = requested;
  std::error_code ec;
  const fs::file_status st = fs::status(requested, ec);
  if (ec && ec != std::errc::no_such_file_or_directory)
    throw io::FileError(io::fileErrorMessage("cannot use the folder", requested, ec.value()));
  if (!fs::exists(st)) {
    io::createDirectories(requested);
  } else if (!fs::is_directory(st)) {
    throw io::FileError(io::fileErrorMessage("cannot use the folder", requested, ENOTDIR));
  }
  if (::access(requested.c_str(), W_OK | X_OK) != 0)
    throw io::FileError(io::fileErrorMessage("cannot write into the folder", requested, errno));
  // The lock first, then the look at the folder: of two commands started at once into a new
  // folder, the second finds it locked, not empty-and-free.
  if (io::lockFolder(requested, /*closeOnExec=*/!keepLockAcrossExec) < 0)
    throw InputError(fmt::format("{} {}: another grainlab {} is writing into this folder now; wait for it to end "
                                 "or give another folder",
                                 option, io::quotedPath(requested), what));
  // The descriptor stays open (and the lock held) until the process ends.
  const bool empty = fs::is_empty(requested, ec);
  if (ec) throw io::FileError(io::fileErrorMessage("cannot read the folder", requested, ec.value()));
  if (empty) {
    f.fresh = true;
    return f;
  }
  if (!fs::is_regular_file(requested / marker, ec))
    throw InputError(fmt::format("{} {}: the folder is not empty and holds no grainlab {} (no {}); a {} writes only "
                                 "into a new or empty folder or its own earlier one: give another folder",
                                 option, io::quotedPath(requested), what, marker, what));
  return f;
}

}  // namespace grainlab::cli

#pragma once
// The folder of a sweep or a calibration (--out), and which folders such a command may write into
// (README "Sweeps", docs/calibration.md) -- the rule of `run` (io/run_folder.hpp) for commands that
// write sweep.csv, report.md, best.toml and plots/ beside their runs:
//
//   - a new or empty folder is the command's;
//   - a folder holding the command's marker file (sweep.json, calibration.json) is its own earlier
//     folder, which the command continues (what is in the marker decides whether it may);
//   - any other non-empty folder is refused (exit 2): it is not the command's to overwrite.
//
// The folder is locked (flock on the folder) for as long as the command runs (for a calibration
// also in the driver it becomes by exec): a second sweep or calibration into it at the same time
// is refused with exit 2.
#include <filesystem>
#include <string>

namespace grainlab::cli {

struct StudyFolder {
  std::filesystem::path dir;
  bool fresh = false;  // new or empty: no earlier results of the command
};

// option: how the folder was given ("sweep --out"); marker: the command's marker file name;
// what: "sweep" or "calibration". keepLockAcrossExec: the lock stays held by the program this
// process becomes with exec (not by the children it starts). Throws InputError for a folder the
// command must not write into or one in use, FileError for a file-system failure.
StudyFolder claimStudyFolder(const std::filesystem::path& requested, const std::string& option,
                             const std::string& marker, const std::string& what, bool keepLockAcrossExec);

}  // namespace grainlab::cli

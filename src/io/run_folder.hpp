#pragma once
// The results folder of a run, and how new results replace earlier ones (README "Results folder").
//
//   - A new or empty folder: the run writes into it directly; there is nothing earlier to protect.
//   - A folder holding earlier grainlab results (it has a config.resolved.toml): the run writes into
//     the hidden sibling .NAME.grainlab-new and, only once it has completed, exchanges the two
//     atomically (renameat2 RENAME_EXCHANGE) and deletes the earlier results. A refused, failed or
//     killed re-run leaves NAME exactly as it was; `grainlab resume NAME` continues a killed re-run
//     from its sibling, and the next `run` into NAME discards it.
//   - Any other non-empty folder is refused: grainlab replaces only its own results.
//   - Files a user added to a results folder (not listed in its manifest, .grainlab-manifest, which a
//     completed run writes last) are kept: a re-run moves them into the new results.
//   - One run at a time: a run or resume holds an exclusive lock (flock) on the results folder for
//     its whole life; a second one into the same folder is refused (InputError) and touches nothing.
//
// A symbolic link as the folder is followed (the results replace its target's contents).
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace grainlab::io {

class RunFolder {
 public:
  // Prepares the folder of a new run into `requested` (creates what is needed). Throws InputError
  // for a folder grainlab must not replace, FileError for a file-system failure.
  static RunFolder forRun(const std::filesystem::path& requested);
  // The InputError forRun would throw for `requested` (a non-empty folder that is not grainlab's),
  // checked without creating anything (for `check`).
  static void checkReplaceable(const std::filesystem::path& requested);
  // The folder a `resume` of `requested` continues in: the staging sibling of a killed re-run when
  // there is one with a checkpoint, else the folder itself.
  static RunFolder forResume(const std::filesystem::path& requested);

  const std::filesystem::path& work() const { return work_; }      // where the run writes
  const std::filesystem::path& target() const { return target_; }  // where the results end up
  bool staged() const { return work_ != target_; }

  // Puts the completed results in place (a no-op when the run wrote there directly).
  void commit();
  // Removes what this run created (after a refused input, or a re-run that failed); a folder that
  // existed and was empty is emptied again; a resumed run in place is left alone.
  void discard();

  // .NAME.grainlab-new beside NAME.
  static std::filesystem::path stagingFolderOf(const std::filesystem::path& target);

  // The manifest of a completed run: the names of the top-level entries the run wrote.
  static constexpr const char* kManifest = ".grainlab-manifest";
  // Writes the manifest of a run's folder (every entry in it now, and the manifest itself).
  static void writeManifest(const std::filesystem::path& dir);

 private:
  std::filesystem::path target_, work_;
  enum class Origin { Created, WasEmpty, Staged, Resumed } origin_ = Origin::Created;
  std::shared_ptr<int> lock_;  // the flock'd descriptor of the target folder, closed with the last copy
  // Takes the folder's lock or throws InputError naming it.
  void lock();
  // After the exchange: moves what a user had added to the earlier results (now in work_) into the
  // new ones.
  void keepUserFiles() const;
};

// Takes an exclusive, non-blocking flock on a folder: the open descriptor that holds it (kept open
// for as long as the lock is to be held), or -1 when another process holds it. A folder that cannot
// be opened or locked: FileError. closeOnExec = false lets a program started by exec inherit it.
int lockFolder(const std::filesystem::path& dir, bool closeOnExec = true);

// The entries of a results folder that a user added: not in its manifest (for a folder without one,
// an earlier grainlab's or a killed run's, not one of the names grainlab writes).
std::vector<std::string> userEntries(const std::filesystem::path& dir);

}  // namespace grainlab::io

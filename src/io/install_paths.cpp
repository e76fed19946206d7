#include "io/install_paths.hpp"

#include <system_error>

#include "io/input_file.hpp"

namespace grainlab::io {

namespace fs = std::filesystem;

fs::path executablePath() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw FileError(fileErrorMessage("cannot find the running executable", "/proc/self/exe", ec.value()));
  return exe;
}

namespace {
fs::path& dataDirOverride() {
  static fs::path dir;
  return dir;
}
}  // namespace

void setDataDir(const fs::path& dir) { dataDirOverride() = dir; }

fs::path dataDir() {
  if (!dataDirOverride().empty()) return dataDirOverride();
  const fs::path bin = executablePath().parent_path();
  for (const fs::path& candidate : {bin.parent_path() / "share" / "grainlab", bin / "share" / "grainlab"}) {
    std::error_code ec;
    if (fs::is_directory(candidate, ec)) return candidate;
  }
  return {};
}

fs::path toolScript(const std::string& name) {
  const fs::path dir = dataDir();
  if (dir.empty()) return {};
  std::error_code ec;
  const fs::path script = dir / "tools" / name;
  return fs::is_regular_file(script, ec) ? script : fs::path{};
}

fs::path presetsDir() {
  const fs::path dir = dataDir();
  return dir.empty() ? fs::path{} : dir / "presets";
}

}  // namespace grainlab::io

#pragma once
// Where the Python tools that the executable starts (calibration driver, Dask runner) are found.
// Today they are read from the source tree, as tools/plot_run.py is; an installed layout only has
// to change this one function.
#include <filesystem>
#include <string>

namespace grainlab::cli {

inline std::filesystem::path toolScript(const std::string& name) {
  return std::filesystem::path(GRAINLAB_SOURCE_DIR) / "tools" / name;
}

}  // namespace grainlab::cli

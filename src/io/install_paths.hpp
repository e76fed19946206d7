#pragma once
// Where grainlab finds its own files at run time: relative to the executable, never through the
// source tree it was built from. An installed program (cmake --install, prefix P) is P/bin/grainlab
// with its data in P/share/grainlab; a build tree holds build/grainlab and build/share/grainlab
// (copied there at build time), so a moved build tree works too.
//
//   share/grainlab/tools/      plot_run.py, plot_sweep.py (started by `run` and `sweep`)
//   share/grainlab/presets/    the presets' data files (presets/data/*.csv); the presets
//                              themselves are compiled into the executable
#include <filesystem>
#include <string>

namespace grainlab::io {

// The running executable (/proc/self/exe).
std::filesystem::path executablePath();
// share/grainlab beside the executable (see above); empty when neither place exists. A host that
// is not the grainlab executable (the Python module inside python3) names the folder instead.
std::filesystem::path dataDir();
void setDataDir(const std::filesystem::path& dir);
// A script of share/grainlab/tools; empty when it is not there.
std::filesystem::path toolScript(const std::string& name);
// Folder that the relative file names of a preset are resolved against (share/grainlab/presets).
std::filesystem::path presetsDir();

}  // namespace grainlab::io

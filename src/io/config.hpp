#pragma once
// Loading, overriding and validating run configurations (TOML, via toml++).
#include <string>
#include <toml++/toml.h>

#include "lab/run_config.hpp"

namespace grainlab::io {

// Reads a config file, or a shipped preset when `source` is "preset:NAME". A file must be a regular
// file within kMaxConfigBytes and nested at most kMaxNesting deep (io/input_file.hpp).
toml::table loadConfigTable(const std::string& source);
// Applies one `--set KEY=VALUE` (dotted key, TOML value; a bare word is taken as a string), within
// the same size and nesting limits as a file.
void applyOverride(toml::table& table, const std::string& assignment);
// Sets output.dir to exactly these bytes (for --out: never parsed as TOML).
void setOutputDir(toml::table& table, const std::string& dir);
// The folder relative file paths of a config are resolved against: the config file's own, or
// share/grainlab/presets for a preset (io/install_paths.hpp).
std::string configBaseDir(const std::string& source);
// Validates every key (unknown keys, types, ranges) and returns the run description.
// Throws InputError with a one-line message naming the key, the value and what is allowed.
// inputFilesMustExist = false: the files a config names (packing, grading list, sphericity file) are
// not required to exist — for `resume`, which never reads them (the state is in the checkpoint), so
// a results folder moved away from its inputs still resumes.
lab::RunConfig parseConfig(const toml::table& table, const std::string& baseDir = "", bool inputFilesMustExist = true);
// Every key with its value, defaults filled in.
toml::table resolvedTable(const lab::RunConfig& config);
std::string toTomlString(const toml::table& table);

}  // namespace grainlab::io

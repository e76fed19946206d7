#pragma once
// Loading, overriding and validating run configurations (TOML, via toml++).
#include <string>
#include <toml++/toml.h>

#include "lab/run_config.hpp"

namespace grainlab::io {

// Reads a config file, or a shipped preset when `source` is "preset:NAME".
toml::table loadConfigTable(const std::string& source);
// Applies one `--set KEY=VALUE` (dotted key, TOML value; a bare word is taken as a string).
void applyOverride(toml::table& table, const std::string& assignment);
// The folder relative file paths of a config are resolved against: the config file's own, or
// presets/ for a preset.
std::string configBaseDir(const std::string& source);
// Validates every key (unknown keys, types, ranges) and returns the run description.
// Throws InputError with a one-line message naming the key, the value and what is allowed.
lab::RunConfig parseConfig(const toml::table& table, const std::string& baseDir = "");
// Every key with its value, defaults filled in.
toml::table resolvedTable(const lab::RunConfig& config);
std::string toTomlString(const toml::table& table);

}  // namespace grainlab::io

#pragma once
// Configurations shipped with grainlab (presets/*.toml, compiled into the executable).
#include <string>
#include <vector>

namespace grainlab::io {

struct Preset {
  std::string name;
  std::string description;  // the first comment line of the file
  std::string toml;
};

const std::vector<Preset>& presets();
const Preset* findPreset(const std::string& name);

}  // namespace grainlab::io

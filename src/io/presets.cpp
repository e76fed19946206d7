#include "io/presets.hpp"

#include <sstream>
#include <utility>

namespace grainlab::io {

const std::vector<std::pair<std::string, std::string>>& presetSources();

const std::vector<Preset>& presets() {
  static const std::vector<Preset> all = [] {
    std::vector<Preset> out;
    for (const auto& [name, body] : presetSources()) {
      std::istringstream in(body);
      std::string line, description;
      while (std::getline(in, line)) {
        if (line.rfind("#", 0) == 0) {
          description = line.substr(line.find_first_not_of("# "));
          break;
        }
      }
      out.push_back({name, description, body});
    }
    return out;
  }();
  return all;
}

const Preset* findPreset(const std::string& name) {
  for (const auto& p : presets())
    if (p.name == name) return &p;
  return nullptr;
}

}  // namespace grainlab::io

#include "io/config.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <filesystem>
#include <set>
#include <sstream>

#include "core/errors.hpp"
#include "io/input_file.hpp"
#include "io/list_files.hpp"
#include "io/install_paths.hpp"
#include "io/presets.hpp"

namespace grainlab::io {

using lab::SphericityConfig;

namespace {

// A value as TOML would write it, floating-point numbers in their shortest exact form (0.7, not
// toml++'s 0.69999999999999996). Nesting is bounded by checkNesting before any config is parsed.
void writeValue(std::ostream& os, const toml::node& node) {
  if (const auto* t = node.as_table()) {
    os << "{ ";
    bool first = true;
    for (const auto& [k, v] : *t) {
      os << (first ? "" : ", ") << k.str() << " = ";
      writeValue(os, v);
      first = false;
    }
    os << " }";
  } else if (const auto* a = node.as_array()) {
    os << "[";
    for (std::size_t i = 0; i < a->size(); ++i) {
      if (i) os << ", ";
      writeValue(os, *a->get(i));
    }
    os << "]";
  } else if (const auto* d = node.as_floating_point()) {
    std::string text = fmt::format("{}", d->get());  // shortest exact form; 1.0 stays a float: "1.0"
    if (text.find_first_of(".eEni") == std::string::npos) text += ".0";
    os << text;
  } else {
    node.visit([&](const auto& v) { os << v; });
  }
}

// A value as the message echoes it: one line, cut to about 80 characters.
std::string show(const toml::node& node) {
  std::ostringstream os;
  writeValue(os, node);
  return printable(os.str());
}

// The value of a number node. toml++ gives no double for an integer that a double cannot hold
// exactly (above 2^53), so integers are converted here (to the nearest double).
double numberOf(const toml::node& node) {
  if (const auto i = node.value_exact<std::int64_t>()) return static_cast<double>(*i);
  return node.value<double>().value();
}

// Nesting of a TOML text (tables of headers and dotted keys, arrays, inline tables), measured
// before the parser sees it: toml++ and the printer of `check` recurse once per level, so a
// file nested 100 000 deep would exhaust the stack. The scan follows strings and comments so that
// brackets and dots inside them do not count.
void checkNesting(std::string_view text, const std::string& subject) {
  int line = 1;
  int base = 0;                  // levels of the current [table] header
  int depth = 0;                 // levels at this point of the current statement
  std::vector<std::pair<char, int>> open;  // '[' or '{' of values, with the depth before it
  bool key = true;               // reading a key (before '=')
  auto deeper = [&](int d) {
    if (d > kMaxNesting)
      throw InputError(fmt::format("{}: line {}: nested deeper than {} levels (tables, arrays, inline tables)", subject,
                                   line, kMaxNesting));
  };
  std::size_t i = 0;
  const std::size_t n = text.size();
  auto skipString = [&](char quote) {
    const bool multi = text.substr(i, 3) == std::string(3, quote);
    i += multi ? 3 : 1;
    while (i < n) {
      const char c = text[i];
      if (c == '\\' && quote == '"') {
        i += 2;
        continue;
      }
      if (c == '\n') {
        ++line;
        if (!multi) return;  // unterminated: the parser reports it
      }
      if (c == quote && (!multi || text.substr(i, 3) == std::string(3, quote))) {
        i += multi ? 3 : 1;
        return;
      }
      ++i;
    }
  };
  while (i < n) {
    const char c = text[i];
    if (c == '"' || c == '\'') {
      skipString(c);
      continue;
    }
    if (c == '#') {
      while (i < n && text[i] != '\n') ++i;
      continue;
    }
    if (c == '\n') {
      ++line;
      if (open.empty()) {
        depth = base;
        key = true;
      }
      ++i;
      continue;
    }
    if (c == '[' && open.empty() && key && depth == base) {
      // A [table] or [[array of tables]] header: one level per dotted part.
      int levels = 1;
      if (i + 1 < n && text[i + 1] == '[') ++levels, ++i;
      ++i;
      while (i < n && text[i] != ']' && text[i] != '\n') {
        if (text[i] == '"' || text[i] == '\'') {
          skipString(text[i]);
          continue;
        }
        if (text[i] == '.') deeper(++levels);
        ++i;
      }
      while (i < n && text[i] == ']') ++i;
      base = depth = levels;
      deeper(base);
      continue;
    }
    if (key && c == '.') {
      deeper(++depth);
    } else if (key && c == '=') {
      key = false;
      deeper(++depth);
    } else if (c == '[' || c == '{') {
      open.emplace_back(c, depth);
      deeper(++depth);
      key = c == '{';
    } else if ((c == ']' || c == '}') && !open.empty()) {
      depth = open.back().second;
      open.pop_back();
      key = false;
    } else if (c == ',' && !open.empty()) {
      depth = open.back().second + 1;
      key = open.back().first == '{';
    }
    ++i;
  }
}

// One rule for relative paths (docs/interface.md): a relative path in a config file names a file
// relative to that config's folder (for a preset: the installed share/grainlab/presets,
// io/install_paths.hpp); a path given with --set (applyOverride) is relative to the working
// directory, made absolute there. Resolved paths are absolute, so the resolved config stays valid
// wherever it is read.
bool pathExists(const std::filesystem::path& path) {
  std::error_code ec;  // a name too long or a folder not searchable: not there
  return std::filesystem::exists(path, ec);
}

std::string resolvePath(const std::string& path, const std::string& baseDir) {
  namespace fs = std::filesystem;
  if (path.empty() || fs::path(path).is_absolute()) return path;
  return fs::absolute(baseDir.empty() ? fs::path(path) : fs::path(baseDir) / path).lexically_normal().string();
}

std::string notFound(const std::string& resolved) {
  return fmt::format("file not found: {} (a relative path in a config file is relative to the config's folder; "
                     "one given with --set, to the working directory)", quotedPath(resolved));
}

// `value` comes already cut (show, quotedPath); the key may be a user's unknown key.
[[noreturn]] void fail(const std::string& key, const std::string& value, const std::string& allowed) {
  throw InputError(fmt::format("config error: {} = {}: {}", printable(key), printable(value, 300), allowed));
}

// Subnormal numbers (0 < |v| < 2.2e-308) have lost their precision and pass every "> 0" check:
// refused wherever a config gives a number.
bool subnormal(double v) { return std::fpclassify(v) == FP_SUBNORMAL; }
constexpr const char* kSubnormal = "is subnormal (0 < |value| < 2.2e-308, below the smallest normal double)";

// Every key of every section and of the inline tables. The unknown-key check runs on all of them
// before any value or cross-key check, so that a misspelt key is reported as such.
const std::vector<std::pair<std::string, std::vector<std::string>>>& knownKeys() {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> keys{
      {"sample",
       {"n_particles", "grading", "density", "e0", "seed", "prep_friction_deg", "e0_tolerance", "initial_void_ratio",
        "packing", "prep_stiffness_factor", "prep_ramp_steps", "prep_damping", "method", "growth_rate",
        "lattice_jitter", "shape", "packing_friction_deg", "drop_height", "gravity", "layers", "under_compaction"}},
      {"contact",
       {"model", "young", "poisson", "friction_deg", "beta", "eta", "wall_friction_deg", "moment_limit", "kn",
        "rolling_friction", "sphericity", "shear_modulus", "rolling", "restitution"}},
      {"test",
       {"type", "boundary", "confining_pressure", "axial_strain_rate", "final_axial_strain", "b", "shear_strain_rate",
        "final_shear_strain", "probe_strain", "unload_reload_at", "platen_slowdown_unbalanced", "rate_follows_pressure", "servo_max_speed",
        "loop_rest", "unload_to_q_fraction", "cs_window", "drainage", "max_axial_stress", "unload_axial_stress", "csr",
        "n_cycles", "ru_limit", "back_pressure", "liquefaction_da_strain", "path", "shear_strain_amplitudes", "cycles_per_amplitude", "aspect_ratio", "membrane_young",
        "membrane_thickness", "membrane_bin_d50", "platen_friction_deg"}},
      {"solver",
       {"damping", "viscous_damping", "dt_factor", "dt", "force_dt", "threads", "unbalanced_tolerance",
        "stress_tolerance", "servo_gain", "servo_integral_steps", "servo_max_speed", "skin_fraction", "max_steps"}},
      {"output",
       {"dir", "record_every_strain", "plots", "save_packing", "checkpoint_every", "vtk_every_strain",
        "micro_snapshots", "band_factor", "band_strain_window"}},
      {"sample.grading", {"type", "diameters", "passing", "d_min", "d_max", "file"}},
      {"sample.shape", {"type", "elongation", "flatness", "orientation", "fraction", "eccentricity_step"}},
      {"contact.sphericity", {"file", "c", "k", "combine"}},
      {"test.path", {"file", "points", "controls", "source"}},
  };
  return keys;
}

const std::vector<std::string>* keysOf(const std::string& table) {
  for (const auto& [name, keys] : knownKeys())
    if (name == table) return &keys;
  return nullptr;
}

std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// "; did you mean ...?" for a near miss (up to 2 edits, or a quarter of the key), or a key of
// another section with this name; empty otherwise.
std::string didYouMean(const std::string& table, const std::string& key) {
  std::string best;
  std::size_t bestDistance = std::max<std::size_t>(2, key.size() / 4) + 1;
  for (const auto& k : *keysOf(table)) {
    const std::size_t d = editDistance(key, k);
    if (d < bestDistance) bestDistance = d, best = table + "." + k;
  }
  if (best.empty())
    for (const auto& [name, keys] : knownKeys())
      if (name != table && name.find('.') == std::string::npos && std::find(keys.begin(), keys.end(), key) != keys.end())
        best = name + "." + key;
  return best.empty() ? std::string() : fmt::format("; did you mean {}?", best);
}

[[noreturn]] void failUnknown(const std::string& table, const std::string& key, const toml::node& value) {
  std::string known;
  for (const auto& k : *keysOf(table)) known += (known.empty() ? "" : ", ") + k;
  // The value of an unknown key matters little: cut shorter than elsewhere, so that the list of
  // known keys fits in one readable line.
  std::ostringstream os;
  writeValue(os, value);
  fail(table + "." + key, printable(os.str(), 32),
       fmt::format("unknown key{}; known keys in {}: {}", didYouMean(table, key),
                   table.find('.') == std::string::npos ? "[" + table + "]" : table, known));
}

// The unknown-key check of the whole config, first of all checks.
void checkUnknownKeys(const toml::table& root) {
  static const std::vector<std::string> sections{"sample", "contact", "test", "solver", "output"};
  for (const auto& [k, v] : root) {
    const std::string section(k.str());
    if (std::find(sections.begin(), sections.end(), section) == sections.end()) {
      std::string near;
      for (const auto& s : sections)
        if (editDistance(section, s) <= 2) near = fmt::format("; did you mean [{}]?", s);
      fail(section, show(v), "unknown section" + near + "; allowed: [sample], [contact], [test], [solver], [output]");
    }
    if (!v.is_table()) fail(section, show(v), "must be a table");
    for (const auto& [key, value] : *v.as_table()) {
      const std::string name(key.str());
      const std::vector<std::string>& keys = *keysOf(section);
      if (std::find(keys.begin(), keys.end(), name) == keys.end()) failUnknown(section, name, value);
      const std::string inner = section + "." + name;
      if (const std::vector<std::string>* sub = keysOf(inner); sub && value.is_table())
        for (const auto& [k2, v2] : *value.as_table())
          if (std::find(sub->begin(), sub->end(), std::string(k2.str())) == sub->end())
            failUnknown(inner, std::string(k2.str()), v2);
    }
  }
}

// One [section] of the config: typed getters with defaults and ranges, and a check that every key
// present was understood.
class Section {
 public:
  Section(const toml::table& root, std::string name) : name_(std::move(name)) {
    const toml::node* node = root.get(name_);
    if (node && !node->is_table()) fail(name_, show(*node), "must be a table");
    table_ = node ? node->as_table() : nullptr;
  }

  const toml::node* raw(const std::string& key) {
    const std::vector<std::string>& keys = *keysOf(name_);
    if (std::find(keys.begin(), keys.end(), key) == keys.end())
      throw std::logic_error("config.cpp: key " + path(key) + " is missing from knownKeys()");
    used_.insert(key);
    return table_ ? table_->get(key) : nullptr;
  }
  std::string path(const std::string& key) const { return name_ + "." + key; }

  double number(const std::string& key, double def, double lo, double hi, bool loOpen, bool hiOpen,
                const std::string& allowed) {
    const toml::node* n = raw(key);
    if (!n) return def;
    if (!n->is_number()) fail(path(key), show(*n), "must be a number; " + allowed);
    const double v = numberOf(*n);
    if (!std::isfinite(v)) fail(path(key), show(*n), "must be a finite number; " + allowed);
    if (subnormal(v)) fail(path(key), show(*n), std::string(kSubnormal) + "; " + allowed);
    if ((loOpen ? v <= lo : v < lo) || (hiOpen ? v >= hi : v > hi)) fail(path(key), show(*n), allowed);
    return v;
  }
  long integer(const std::string& key, long def, long lo, long hi) {
    const toml::node* n = raw(key);
    if (!n) return def;
    const std::string allowed = fmt::format("must be an integer in [{}, {}]", lo, hi);
    if (!n->is_integer()) fail(path(key), show(*n), allowed);
    const long v = static_cast<long>(n->value<std::int64_t>().value());
    if (v < lo || v > hi) fail(path(key), show(*n), allowed);
    return v;
  }
  bool boolean(const std::string& key, bool def) {
    const toml::node* n = raw(key);
    if (!n) return def;
    if (!n->is_boolean()) fail(path(key), show(*n), "must be true or false");
    return n->value<bool>().value();
  }
  std::string string(const std::string& key, const std::string& def,
                     const std::vector<std::string>& allowed) {
    const toml::node* n = raw(key);
    if (!n) return def;
    std::string choices;
    for (const auto& a : allowed) choices += (choices.empty() ? "\"" : ", \"") + a + "\"";
    if (!n->is_string()) fail(path(key), show(*n), "must be a string" + (allowed.empty() ? std::string() : " out of " + choices));
    std::string v = n->value<std::string>().value();
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), v) == allowed.end())
      fail(path(key), show(*n), "allowed: " + choices);
    return v;
  }
  std::vector<double> numbers(const toml::node& node, const std::string& key) {
    if (!node.is_array()) fail(key, show(node), "must be an array of numbers");
    std::vector<double> out;
    for (const auto& e : *node.as_array()) {
      if (!e.is_number() || !std::isfinite(numberOf(e))) fail(key, show(node), "must be an array of finite numbers");
      if (subnormal(numberOf(e))) fail(key, show(node), std::string("an element ") + kSubnormal);
      out.push_back(numberOf(e));
    }
    return out;
  }
  // Every key must be known: a misspelt key is an error, not silently ignored.
  void finish(const std::vector<std::string>& extraKnown = {}) {
    if (!table_) return;
    for (const auto& [k, v] : *table_) {
      const std::string key(k.str());
      if (used_.count(key) || std::find(extraKnown.begin(), extraKnown.end(), key) != extraKnown.end())
        continue;
      failUnknown(name_, key, v);
    }
  }

 private:
  std::string name_;
  const toml::table* table_ = nullptr;
  std::set<std::string> used_;
};

lab::GradingConfig parseGrading(Section& s, const std::string& baseDir, bool mustExist) {
  lab::GradingConfig g;
  const toml::node* node = s.raw("grading");
  if (!node) return g;
  const std::string key = s.path("grading");
  if (!node->is_table()) fail(key, show(*node), "must be an inline table, e.g. { type = \"uniform\", d_min = 2e-3, d_max = 8e-3 }");
  const toml::table& t = *node->as_table();
  std::set<std::string> known;
  auto get = [&](const char* k) { known.insert(k); return t.get(k); };
  const toml::node* type = get("type");
  if (!type || !type->is_string())
    fail(key + ".type", type ? show(*type) : "(missing)", "allowed: \"curve\", \"uniform\", \"list\" (\"packing\" with sample.packing)");
  g.type = type->value<std::string>().value();
  // Diameters within [kMinDiameter, kMaxDiameter]: a grain of 1e-300 m or 1e300 m is no test.
  const std::string range = fmt::format("[{:g}, {:g}] m", lab::kMinDiameter, lab::kMaxDiameter);
  auto inRange = [](double d) { return d >= lab::kMinDiameter && d <= lab::kMaxDiameter; };
  if (g.type == "curve") {
    const toml::node* d = get("diameters");
    const toml::node* p = get("passing");
    if (!d) fail(key + ".diameters", "(missing)", "an array of sieve diameters [m] is required");
    if (!p) fail(key + ".passing", "(missing)", "an array of percent passing by mass is required");
    g.diameters = s.numbers(*d, key + ".diameters");
    g.passing = s.numbers(*p, key + ".passing");
    if (g.diameters.size() < 2 || g.diameters.size() != g.passing.size())
      fail(key + ".passing", show(*p), "must have one value per diameter (at least 2)");
    for (std::size_t i = 0; i < g.diameters.size(); ++i) {
      if (!inRange(g.diameters[i])) fail(key + ".diameters", show(*d), "every diameter must be in " + range);
      if (i > 0 && !(g.diameters[i] > g.diameters[i - 1])) fail(key + ".diameters", show(*d), "diameters must increase strictly");
      if (i > 0 && g.passing[i] < g.passing[i - 1]) fail(key + ".passing", show(*p), "percent passing must not decrease");
    }
    if (g.passing.front() != 0.0 || g.passing.back() != 100.0)
      fail(key + ".passing", show(*p), "must start at 0 and end at 100 (percent passing by mass)");
  } else if (g.type == "uniform") {
    const toml::node* lo = get("d_min");
    const toml::node* hi = get("d_max");
    if (!lo || !lo->is_number()) fail(key + ".d_min", lo ? show(*lo) : "(missing)", "a diameter in " + range + " is required");
    if (!hi || !hi->is_number()) fail(key + ".d_max", hi ? show(*hi) : "(missing)", "a diameter >= d_min in " + range + " is required");
    g.dMin = numberOf(*lo);
    g.dMax = numberOf(*hi);
    if (!inRange(g.dMin)) fail(key + ".d_min", show(*lo), "must be a diameter in " + range);
    if (!(g.dMax >= g.dMin) || !inRange(g.dMax))
      fail(key + ".d_max", show(*hi), fmt::format("must be a diameter in [d_min = {:g}, {:g}] m", g.dMin, lab::kMaxDiameter));
  } else if (g.type == "list") {
    const toml::node* f = get("file");
    if (!f || !f->is_string()) fail(key + ".file", f ? show(*f) : "(missing)", "a path to a file of diameters [m] is required");
    g.file = resolvePath(f->value<std::string>().value(), baseDir);
    if (mustExist && !pathExists(g.file)) fail(key + ".file", show(*f), notFound(g.file));
    // Read here, so the laboratory gets the diameters and `check` checks the file (not for resume,
    // whose grains are in the checkpoint).
    if (mustExist) g.list = readDiameterList(g.file);
  } else if (g.type == "packing") {
    // The grading of a packing file is its own (recorded so in config.resolved.toml).
    if (!s.raw("packing")) fail(key + ".type", show(*type), "\"packing\" is the grading of sample.packing; give sample.packing");
  } else {
    fail(key + ".type", show(*type), "allowed: \"curve\", \"uniform\", \"list\" (\"packing\" with sample.packing)");
  }
  for (const auto& [k, v] : t)
    if (!known.count(std::string(k.str())))
      fail(key + "." + std::string(k.str()), show(v), "unknown key for grading type \"" + g.type + "\"");
  return g;
}

// A string with a NUL character would be cut short where it is used as a path (the C library
// stops there), so a path could name another file than the one written: refused everywhere.
void refuseNulCharacters(const toml::node& node, const std::string& key) {
  if (const auto* t = node.as_table()) {
    for (const auto& [k, v] : *t) refuseNulCharacters(v, key.empty() ? std::string(k.str()) : key + "." + std::string(k.str()));
  } else if (const auto* a = node.as_array()) {
    for (const auto& v : *a) refuseNulCharacters(v, key);
  } else if (const auto* str = node.as_string()) {
    if (str->get().find('\0') != std::string::npos) fail(key, show(node), "must not contain a NUL character");
  }
}

lab::ShapeConfig parseShape(Section& s) {
  lab::ShapeConfig shape;
  const toml::node* node = s.raw("shape");
  if (!node) return shape;
  const std::string key = s.path("shape");
  if (!node->is_table())
    fail(key, show(*node), "must be an inline table, e.g. { type = \"ellipsoid\", elongation = 0.7, flatness = 1.0 }");
  const toml::table& t = *node->as_table();
  for (const auto& [k, v] : t) {
    const std::string name(k.str());
    if (name != "type" && name != "elongation" && name != "flatness" && name != "orientation" && name != "fraction" &&
        name != "eccentricity_step")
      fail(key + "." + name, show(v), "unknown key; allowed: type, elongation, flatness, orientation, fraction, eccentricity_step");
  }
  auto number = [&](const char* k, double def, double lo, double hi, const char* allowed) {
    const toml::node* n = t.get(k);
    if (!n) return def;
    const std::optional<double> v = n->value<double>();
    if (!n->is_number() || !v || !std::isfinite(*v) || subnormal(*v) || *v <= lo || *v > hi) fail(key + "." + k, show(*n), allowed);
    return *v;
  };
  auto text = [&](const char* k, const std::string& def, const std::vector<std::string>& allowed) {
    const toml::node* n = t.get(k);
    if (!n) return def;
    const std::string v = n->is_string() ? n->value<std::string>().value() : std::string();
    if (std::find(allowed.begin(), allowed.end(), v) == allowed.end()) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "\"" : ", \"") + a + "\"";
      fail(key + "." + k, show(*n), "allowed: " + list);
    }
    return v;
  };
  shape.type = text("type", shape.type, {"sphere", "ellipsoid"});
  shape.elongation = number("elongation", shape.elongation, 0.0, 1.0, "must be in (0, 1] (b/a)");
  shape.flatness = number("flatness", shape.flatness, 0.0, 1.0, "must be in (0, 1] (c/b)");
  shape.orientation = text("orientation", shape.orientation, {"random", "aligned-x"});
  shape.fraction = number("fraction", shape.fraction, 0.0, 1.0, "must be in (0, 1] (share of ellipsoids by number)");
  shape.eccentricityStep = number("eccentricity_step", shape.eccentricityStep, 0.0, 0.5, "must be in (0, 0.5]");
  if (shape.type == "ellipsoid" && shape.elongation == 1.0 && shape.flatness == 1.0)
    fail(key + ".elongation", "1", "an ellipsoid needs elongation < 1 or flatness < 1 (else type = \"sphere\")");
  return shape;
}

// Why a key cannot apply under the rest of the config `c`, or "" where it applies. A key given
// (whatever its value, its default included) that cannot apply is refused; config.resolved.toml
// and `check` write exactly the keys that apply, so that a resolved config is itself a valid config.
std::string inapplicable(const lab::RunConfig& c, const std::string& key) {
  const bool packing = !c.sample.packing.empty();
  const std::string& method = c.sample.method;
  const std::string type(lab::name(c.test.type));
  const lab::TestType tt = c.test.type;
  const bool searched = method == "compaction" || method == "loose-moment-free";
  const bool shear = lab::shears(tt);
  const bool monotonicAxial = tt == lab::TestType::Triaxial || tt == lab::TestType::ConstantP || tt == lab::TestType::TrueTriaxial;
  auto here = [](const char* k, const std::string& v) { return fmt::format("here {} = \"{}\"", k, v); };
  static const std::set<std::string> preparation{
      "sample.e0",           "sample.e0_tolerance", "sample.prep_friction_deg", "sample.initial_void_ratio",
      "sample.prep_stiffness_factor", "sample.prep_ramp_steps", "sample.prep_damping", "sample.method",
      "sample.growth_rate",  "sample.lattice_jitter", "sample.shape", "sample.drop_height", "sample.layers",
      "sample.under_compaction"};
  if (packing && (preparation.count(key) || key.rfind("sample.shape.", 0) == 0))
    return "not used with sample.packing (a packing file is taken as it is: no preparation)";
  if (!packing && key == "sample.packing_friction_deg")
    return "only used with sample.packing (the friction while a given packing is brought to the test's pressure)";
  if (!packing && key == "sample.grading" && c.sample.grading.type == "packing")
    return "{ type = \"packing\" } needs sample.packing";
  if (key == "sample.growth_rate" && method != "growth")
    return "only used with sample.method = \"growth\"; " + here("sample.method", method);
  if (key == "sample.prep_friction_deg" && (method == "deposition" || method == "under-compaction"))
    return "";  // the friction of the rain (and of the tamping)
  // Under-compaction tamps the layers to the densities of e0: e0 is its target, not searched.
  if ((key == "sample.e0" || key == "sample.e0_tolerance") && method == "under-compaction") return "";
  if ((key == "sample.layers" || key == "sample.under_compaction") && method != "under-compaction")
    return "only used with sample.method = \"under-compaction\"; " + here("sample.method", method);
  if ((key == "sample.e0" || key == "sample.e0_tolerance" || key == "sample.prep_friction_deg") && !searched)
    return "only used with sample.method = \"compaction\" or \"loose-moment-free\" (" +
           (method == "deposition" ? std::string("a deposited sample") : "a frictionless " + method) +
           " reaches its own e0); " + here("sample.method", method);
  if (key == "sample.drop_height" && method != "deposition")
    return "only used with sample.method = \"deposition\"; " + here("sample.method", method);
  if (key == "sample.initial_void_ratio" && method == "lattice")
    return "not used with sample.method = \"lattice\" (no loose placement)";
  if (key.rfind("sample.shape.", 0) == 0 && key != "sample.shape.type" && c.sample.shape.type != "ellipsoid")
    return "only used with sample.shape.type = \"ellipsoid\"; " + here("sample.shape.type", c.sample.shape.type);
  const bool hertz = c.contact.hertz();
  const std::string& slot = c.contact.rollingSlot();
  const std::string slotHere = hertz ? here("contact.rolling", c.contact.rolling) : here("contact.model", c.contact.model);
  if ((key == "contact.beta" || key == "contact.eta" || key == "contact.moment_limit") && slot != "kozicki")
    return "only used with the Kozicki–Donze moments (contact.model = \"kozicki\", or \"hertz-mindlin\" with "
           "contact.rolling = \"kozicki\"); " + slotHere;
  if ((key == "contact.rolling_friction" || key == "contact.sphericity") && slot != "rolling-linear")
    return "only used with the linear rolling resistance (contact.model = \"rolling-linear\", or \"hertz-mindlin\" "
           "with contact.rolling = \"rolling-linear\"); " + slotHere;
  if ((key == "contact.shear_modulus" || key == "contact.rolling" || key == "contact.restitution") && !hertz)
    return "only used with contact.model = \"hertz-mindlin\"; " + here("contact.model", c.contact.model);
  if ((key == "contact.young" || key == "contact.kn") && hertz)
    return "not used with contact.model = \"hertz-mindlin\" (its stiffness follows from contact.shear_modulus and "
           "contact.poisson)";
  if (key == "contact.rolling_friction" && c.contact.sphericity)
    return "give either contact.rolling_friction or contact.sphericity, not both";
  if (key == "contact.wall_friction_deg" && c.test.boundary == "periodic")
    return "a periodic cell has no walls; " + here("test.boundary", c.test.boundary);
  if ((key == "test.aspect_ratio" || key == "test.membrane_young" || key == "test.membrane_thickness" ||
       key == "test.membrane_bin_d50") && c.test.boundary != "membrane")
    return "only used with test.boundary = \"membrane\"; " + here("test.boundary", c.test.boundary);
  if (key == "test.platen_friction_deg" && c.test.boundary == "periodic")
    return "a periodic cell has no platens; " + here("test.boundary", c.test.boundary);
  if (key == "contact.young" && c.contact.kn)
    return "not used with contact.kn (every contact has the constant normal stiffness kn)";
  if (key == "test.b" && type != "true-triaxial")
    return "only used with test.type = \"true-triaxial\"; " + here("test.type", type);
  if (key == "test.axial_strain_rate" && lab::info(tt).strain != lab::DrivingStrain::Axial)
    return "only used with test.type = \"triaxial\", \"constant-p\", \"true-triaxial\", \"oedometer\", "
           "\"cyclic-triaxial\" or \"stress-path\"; " + here("test.type", type);
  if (key == "test.final_axial_strain" && !monotonicAxial && tt != lab::TestType::StressPath)
    return "only used with test.type = \"triaxial\", \"constant-p\", \"true-triaxial\" or \"stress-path\"; " +
           here("test.type", type);
  if (key == "test.path" && tt != lab::TestType::StressPath)
    return "only used with test.type = \"stress-path\"; " + here("test.type", type);
  if (key == "test.cs_window" && !monotonicAxial && tt != lab::TestType::SimpleShear)
    return "only used with the monotonic shearing tests (test.type = \"triaxial\", \"constant-p\", \"true-triaxial\" "
           "or \"simple-shear\"); " + here("test.type", type);
  if (key == "test.shear_strain_rate" && lab::info(tt).strain != lab::DrivingStrain::Shear)
    return "only used with test.type = \"simple-shear\" or \"cyclic-simple-shear\"; " + here("test.type", type);
  if (key == "test.final_shear_strain" && tt != lab::TestType::SimpleShear)
    return "only used with test.type = \"simple-shear\"; " + here("test.type", type);
  if ((key == "test.shear_strain_amplitudes" || key == "test.cycles_per_amplitude") &&
      tt != lab::TestType::CyclicSimpleShear)
    return "only used with test.type = \"cyclic-simple-shear\"; " + here("test.type", type);
  if (key == "test.drainage" && !lab::info(tt).drainage)
    return "only used with test.type = \"triaxial\", \"simple-shear\", \"cyclic-triaxial\" or \"cyclic-simple-shear\"; " +
           here("test.type", type);
  if ((key == "test.max_axial_stress" || key == "test.unload_axial_stress") && tt != lab::TestType::Oedometer)
    return "only used with test.type = \"oedometer\"; " + here("test.type", type);
  if ((key == "test.csr" || key == "test.n_cycles" || key == "test.liquefaction_da_strain") && tt != lab::TestType::CyclicTriaxial)
    return "only used with test.type = \"cyclic-triaxial\"; " + here("test.type", type);
  if (key == "test.ru_limit" && tt != lab::TestType::CyclicTriaxial &&
      !(lab::info(tt).drainage && c.test.drainage == lab::Drainage::Undrained))
    return "only used with test.type = \"cyclic-triaxial\" or an undrained test (test.drainage = \"undrained\")";
  if (key == "test.back_pressure" && !(lab::info(tt).drainage && c.test.drainage == lab::Drainage::Undrained))
    return "only used with an undrained test (test.drainage = \"undrained\": the pore water's back pressure sets "
           "where it cavitates)";
  if ((key == "test.unload_to_q_fraction" || key == "test.loop_rest") && c.test.unloadReloadAt.empty())
    return "only used with test.unload_reload_at (unload-reload loops)";
  if ((key == "test.platen_slowdown_unbalanced" || key == "test.servo_max_speed" || key == "test.rate_follows_pressure") &&
      !shear)
    return "not used with test.type = \"isotropic\" (no shearing)";
  if (key == "solver.force_dt" && !c.solver.dt) return "only used with solver.dt (it allows a dt above the critical step)";
  if (key == "solver.damping" && c.solver.viscousDamping > 0.0)
    return fmt::format("not used with solver.viscous_damping = {} > 0 (viscous damping replaces the local damping)",
                       c.solver.viscousDamping);
  if (key == "output.micro_snapshots" && c.output.microSnapshots && c.output.vtkEveryStrain == 0.0)
    return "the contact-network snapshots are taken with the VTK ones, and output.vtk_every_strain = 0";
  return "";
}

// Refuses every key given that cannot apply, naming it and the key that rules it out. The
// preparation keys beside sample.packing are the exception: a config that prepared a sample is meant
// to be reused with --set sample.packing=... (its packing.txt); they are ignored with a warning
// (lab::RunConfig::warnings, printed by `check` and `run` and kept in the summary).
void refuseInapplicable(const toml::table& root, lab::RunConfig& c) {
  for (const auto& [table, keys] : knownKeys())
    for (const auto& k : keys) {
      const std::string key = table + "." + k;
      const toml::node* node = root.at_path(key).node();
      if (!node) continue;
      std::string why = inapplicable(c, key);
      if (key == "sample.grading" && !c.sample.packing.empty()) {
        const toml::node* type = node->is_table() ? node->as_table()->get("type") : nullptr;
        if (!type || type->value<std::string>() != std::optional<std::string>("packing"))
          why = "not used with sample.packing (the packing brings its own grains)";
      }
      // solver.damping = 0 beside a viscous damping states "no local damping": consistent, kept.
      if (key == "solver.damping" && node->is_number() && numberOf(*node) == 0.0) continue;
      if (why.empty()) continue;
      // Ignoring is intended for the targets of a preparation that does not use them (a config
      // reused with a packing, or with another sample.method): a warning, not an error.
      const bool preparationTarget = key == "sample.e0" || key == "sample.e0_tolerance" || key == "sample.prep_friction_deg";
      // So is a config of one test reused for another with --set test.type=... (a preset's axial
      // rate when it is run as an isotropic or simple-shear test): the other test's keys warn.
      static const std::set<std::string> testTypeKeys{
          "test.b", "test.axial_strain_rate", "test.final_axial_strain", "test.shear_strain_rate",
          "test.final_shear_strain", "test.platen_slowdown_unbalanced", "test.rate_follows_pressure", "test.servo_max_speed",
          "test.cs_window",
          "test.drainage", "test.max_axial_stress", "test.unload_axial_stress", "test.csr", "test.n_cycles",
          "test.ru_limit", "test.back_pressure", "test.liquefaction_da_strain", "test.path", "test.shear_strain_amplitudes",
          "test.cycles_per_amplitude"};
      const bool otherTestsKey = testTypeKeys.count(key) > 0;
      // And a linear-law config run with Hertz–Mindlin (--set contact.model="hertz-mindlin" on a
      // preset): the linear law's parameters warn. Between the linear laws, and Hertz–Mindlin's own
      // keys under a linear law, a key that cannot apply stays an error.
      static const std::set<std::string> linearLawKeys{"contact.young", "contact.kn", "contact.beta", "contact.eta",
                                                       "contact.moment_limit"};
      const bool otherLawKey = c.contact.hertz() && linearLawKeys.count(key) > 0;
      if ((!c.sample.packing.empty() && why.find("sample.packing") != std::string::npos) || preparationTarget ||
          otherTestsKey || otherLawKey) {
        c.warnings.push_back(fmt::format("{} = {} is ignored: {}", key, printable(show(*node)), why));
        continue;
      }
      fail(key, show(*node), "cannot apply: " + why + fmt::format(" (remove {})", key));
    }
}

}  // namespace

std::string configBaseDir(const std::string& source) {
  if (source.rfind("preset:", 0) == 0) return presetsDir().string();
  return std::filesystem::absolute(source).parent_path().string();
}

toml::table loadConfigTable(const std::string& source) {
  std::string text, name;
  if (source.rfind("preset:", 0) == 0) {
    const std::string preset = source.substr(7);
    const Preset* p = findPreset(preset);
    if (!p) {
      std::string names;
      for (const auto& q : presets()) names += (names.empty() ? "" : ", ") + q.name;
      throw InputError(fmt::format("unknown preset \"{}\"; available: {}", printable(preset), names));
    }
    text = p->toml;
    name = "preset:" + preset;
  } else {
    const std::string subject = fmt::format("config file {}", quotedPath(source));
    text = readInputFile(source, subject, kMaxConfigBytes);
    checkNesting(text, subject);
    name = source;
  }
  try {
    return toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("config error: {} line {}: {}", quotedPath(name), e.source().begin.line,
                                 printable(e.description(), 160)));
  }
}

namespace {
// The keys that name input files.
bool isPathKey(const std::string& key) {
  return key == "sample.packing" || key == "sample.grading.file" || key == "contact.sphericity.file" ||
         key == "test.path.file";
}
// A relative path given with --set is relative to the working directory: made absolute here, before
// the config's folder is applied to the config's own relative paths.
void absolutizePaths(toml::node& node, const std::string& key) {
  if (auto* t = node.as_table()) {
    for (auto&& [k, v] : *t) absolutizePaths(v, key + "." + std::string(k.str()));
  } else if (auto* str = node.as_string(); str && isPathKey(key)) {
    const std::string path = str->get();
    if (!path.empty() && path.find('\0') == std::string::npos && !std::filesystem::path(path).is_absolute())
      str->get() = std::filesystem::absolute(path).lexically_normal().string();
  }
}
}  // namespace

void applyOverride(toml::table& table, const std::string& assignment) {
  const std::string shown = printable(assignment);
  if (assignment.size() > kMaxConfigBytes)
    throw InputError(fmt::format("--set {}: longer than the limit of {} bytes", shown, kMaxConfigBytes));
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(fmt::format("--set {}: expected KEY=VALUE with a dotted key, e.g. contact.beta=0", shown));
  const std::string key = assignment.substr(0, eq);
  const std::string value = assignment.substr(eq + 1);
  if (std::count(key.begin(), key.end(), '.') >= kMaxNesting)
    throw InputError(fmt::format("--set {}: the key is nested deeper than {} levels", shown, kMaxNesting));
  const std::string document = "v = " + value;
  checkNesting(document, fmt::format("--set {}", shown));
  toml::table parsed;
  try {
    parsed = toml::parse(document);
  } catch (const toml::parse_error&) {
    // A bare word (e.g. model=rolling-linear) is meant as a string.
    toml::table t;
    t.insert("v", value);
    parsed = std::move(t);
  }
  toml::table* cur = &table;
  std::size_t start = 0;
  while (true) {
    const auto dot = key.find('.', start);
    const std::string part = key.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (part.empty()) throw InputError(fmt::format("--set {}: empty component in key \"{}\"", shown, printable(key)));
    if (dot == std::string::npos) {
      absolutizePaths(*parsed.get("v"), key);
      cur->insert_or_assign(part, *parsed.get("v"));
      return;
    }
    toml::node* next = cur->get(part);
    if (!next) {
      cur->insert(part, toml::table{});
      next = cur->get(part);
    }
    if (!next->is_table())
      throw InputError(fmt::format("--set {}: \"{}\" is not a table", shown, printable(key.substr(0, dot))));
    cur = next->as_table();
    start = dot + 1;
  }
}

void setOutputDir(toml::table& table, const std::string& dir) {
  toml::node* output = table.get("output");
  if (!output) {
    table.insert("output", toml::table{});
    output = table.get("output");
  }
  if (!output->is_table()) throw InputError(fmt::format("config error: output = {}: must be a table", show(*output)));
  output->as_table()->insert_or_assign("dir", dir);
}

// test.path: { file = "path.csv" } (read and checked here, lab/stress_path.hpp), or the points
// inline, { points = [[s, xx, yy, zz], ...], controls = [["stress", "stress", "strain"], ...] }, the
// form config.resolved.toml keeps so that a resumed run follows the same path whatever became of
// the file (source names it).
void parseStressPath(const toml::node& node, const std::string& baseDir, bool mustExist, lab::TestConfig& test) {
  const std::string key = "test.path";
  if (!node.is_table())
    fail(key, show(node), "must be an inline table { file = \"path.csv\" } or { points = [[s, xx, yy, zz], ...], "
                          "controls = [[\"stress\", \"stress\", \"strain\"], ...] }");
  const toml::table& t = *node.as_table();
  const toml::node* file = t.get("file");
  const toml::node* points = t.get("points");
  const toml::node* controls = t.get("controls");
  if (const toml::node* src = t.get("source")) {
    if (!src->is_string()) fail(key + ".source", show(*src), "must be a string (the file the points came from)");
    test.pathSource = src->value<std::string>().value();
  }
  if (file && points) fail(key + ".points", show(*points), "give either test.path.file or test.path.points, not both");
  if (file) {
    if (!file->is_string()) fail(key + ".file", show(*file), "must be a path to a CSV of path points");
    const std::string path = resolvePath(file->value<std::string>().value(), baseDir);
    test.pathSource = path;
    if (!mustExist && !pathExists(path)) return;
    if (!pathExists(path)) fail(key + ".file", show(*file), notFound(path));
    test.path = readStressPathFile(path, key + ".file");
    return;
  }
  if (!points) fail(key, show(node), "needs file = \"path.csv\" (or points with controls)");
  if (!points->is_array() || points->as_array()->empty())
    fail(key + ".points", show(*points), "must be a non-empty array of [s, xx, yy, zz]");
  if (!controls || !controls->is_array() || controls->as_array()->size() != points->as_array()->size())
    fail(key + ".controls", controls ? show(*controls) : "(missing)",
         "must be an array with one [xx, yy, zz] of \"stress\" or \"strain\" per point");
  if (points->as_array()->size() > lab::kMaxPathPoints)
    fail(key + ".points", fmt::format("({} points)", points->as_array()->size()),
         fmt::format("at most {} points", lab::kMaxPathPoints));
  for (std::size_t i = 0; i < points->as_array()->size(); ++i) {
    const toml::node& pn = *points->as_array()->get(i);
    const toml::node& cn = *controls->as_array()->get(i);
    const std::string pk = fmt::format("{}.points[{}]", key, i), ck = fmt::format("{}.controls[{}]", key, i);
    const toml::array* pa = pn.as_array();
    if (!pa || pa->size() != 4) fail(pk, show(pn), "must be [s, xx, yy, zz] (four numbers)");
    const toml::array* ca = cn.as_array();
    if (!ca || ca->size() != 3) fail(ck, show(cn), "must be [xx, yy, zz], each \"stress\" or \"strain\"");
    lab::PathPoint p;
    for (std::size_t k = 0; k < 4; ++k) {
      const toml::node& e = *pa->get(k);
      if (!e.is_number() || !std::isfinite(numberOf(e)) || subnormal(numberOf(e)))
        fail(pk, show(pn), "must be four finite, normal numbers [s, xx, yy, zz]");
      (k == 0 ? p.s : p.value[k - 1]) = numberOf(e);
    }
    for (std::size_t k = 0; k < 3; ++k) {
      const std::optional<std::string> text = ca->get(k)->value<std::string>();
      const std::optional<lab::PathControl> control = text ? lab::parseControl(*text) : std::nullopt;
      if (!control) fail(ck, show(cn), "each control must be \"stress\" or \"strain\"");
      p.control[k] = *control;
    }
    if (const std::string why = lab::checkPathPoint(p, test.path.empty() ? 0.0 : test.path.back().s); !why.empty())
      fail(pk, show(pn), why);
    test.path.push_back(p);
  }
}

lab::RunConfig parseConfig(const toml::table& root, const std::string& baseDir, bool inputFilesMustExist) {
  checkUnknownKeys(root);
  refuseNulCharacters(root, "");
  lab::RunConfig c;

  Section s(root, "sample");
  c.sample.nParticlesGiven = s.raw("n_particles") != nullptr;
  c.sample.nParticles = static_cast<int>(s.integer("n_particles", c.sample.nParticles, 2, 50'000'000));
  c.sample.grading = parseGrading(s, baseDir, inputFilesMustExist);
  c.sample.density = s.number("density", c.sample.density, 1.0, 1e6, false, false, "must be in [1, 1e6] [kg/m^3]");
  c.sample.e0 = s.number("e0", c.sample.e0, 0.0, 5.0, true, false, "must be > 0 and <= 5 (void ratio)");
  c.sample.seed = static_cast<std::uint64_t>(s.integer("seed", 1, 0, std::numeric_limits<std::int64_t>::max()));
  if (const toml::node* n = s.raw("prep_friction_deg")) {
    if (n->is_string() && n->value<std::string>().value() == "auto") {
      c.sample.prepFrictionDeg.reset();
    } else {
      c.sample.prepFrictionDeg = s.number("prep_friction_deg", 0.0, 0.0, 90.0, false, true,
                                         "must be \"auto\" or an angle in [0, 90) [deg]");
    }
  }
  c.sample.e0Tolerance = s.number("e0_tolerance", c.sample.e0Tolerance, 0.0, 1.0, true, false, "must be in (0, 1]");
  c.sample.initialVoidRatio = s.number("initial_void_ratio", c.sample.initialVoidRatio, 1.0, 20.0, false, false,
                                       "must be in [1, 20] (loose placement before compaction)");
  c.sample.packing = resolvePath(s.string("packing", c.sample.packing, {}), baseDir);
  if (inputFilesMustExist && !c.sample.packing.empty() && !pathExists(c.sample.packing))
    fail("sample.packing", quotedPath(c.sample.packing), notFound(c.sample.packing));
  if (s.raw("packing_friction_deg"))
    c.sample.packingFrictionDeg = s.number("packing_friction_deg", 0.0, 0.0, 90.0, false, true,
                                           "must be an angle in [0, 90) [deg]");
  c.sample.prepStiffnessFactor = s.number("prep_stiffness_factor", c.sample.prepStiffnessFactor, 0.0, 1.0, true, false,
                                          "must be in (0, 1] (contact stiffness during compaction as a fraction of contact.young)");
  c.sample.prepRampSteps = s.integer("prep_ramp_steps", c.sample.prepRampSteps, 1, 100'000'000);
  c.sample.prepDamping = s.number("prep_damping", c.sample.prepDamping, 0.0, 1.0, false, true, "must be in [0, 1)");
  c.sample.method = s.string("method", c.sample.method,
                             {"compaction", "growth", "lattice", "loose-moment-free", "deposition", "under-compaction"});
  c.sample.layers = static_cast<int>(s.integer("layers", c.sample.layers, 2, 50));
  // Every layer is a cloud of its own: an empty one has nothing to place (and a layer of a few grains
  // is no layer).
  if (c.sample.method == "under-compaction" && c.sample.layers > c.sample.nParticles / 10)
    fail("sample.layers", std::to_string(c.sample.layers),
         fmt::format("allowed: at most sample.n_particles / 10 = {} (each layer needs 10 grains or more; "
                     "under-compaction needs sample.n_particles >= 20)",
                     c.sample.nParticles / 10));
  c.sample.underCompaction = s.number("under_compaction", c.sample.underCompaction, 0.0, 0.3, false, false,
                                      "must be in [0, 0.3] (the bottom layer's dry density below that of e0, as a "
                                      "fraction; 0: every layer tamped to e0)");
  const bool rained = c.sample.method == "deposition" || c.sample.method == "under-compaction";
  c.sample.dropHeight = s.number("drop_height", c.sample.dropHeight, 0.0, 10.0, false, false,
                                 "must be in [0, 10] [m] (free fall of the lowest grains of the cloud above the floor)");
  if (const toml::node* n = s.raw("gravity")) {
    const std::string key = s.path("gravity");
    const std::vector<double> g = s.numbers(*n, key);
    if (g.size() != 3) fail(key, show(*n), "must be an array of three numbers [gx, gy, gz] [m/s^2]");
    const double norm = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (norm > 1000.0) fail(key, show(*n), "|g| must be <= 1000 m/s^2 (about 100 times the Earth's)");
    c.sample.gravity = std::array<double, 3>{g[0], g[1], g[2]};
  }
  if (rained) {
    if (!c.sample.gravity) c.sample.gravity = std::array<double, 3>{0.0, 0.0, -9.81};
    const auto& g = *c.sample.gravity;
    if (!(g[0] == 0.0 && g[1] == 0.0 && g[2] < 0.0))
      fail("sample.gravity", fmt::format("[{}, {}, {}]", g[0], g[1], g[2]),
           fmt::format("sample.method = \"{}\" rains the grains down the z axis onto the floor: allowed [0, 0, -g] with "
                       "g > 0 (default [0, 0, -9.81])", c.sample.method));
  }
  c.sample.growthRate = s.number("growth_rate", c.sample.growthRate, 0.0, 0.01, true, false,
                                 "must be in (0, 0.01] (relative radius growth per step)");
  c.sample.latticeJitter = s.number("lattice_jitter", c.sample.latticeJitter, 0.0, 0.05, false, false,
                                    "must be in [0, 0.05] (random lattice site offsets, fraction of the diameter)");
  c.sample.shape = parseShape(s);
  if (rained && c.sample.shape.type == "ellipsoid")
    fail("sample.method", "\"" + c.sample.method + "\"",
         "is for spheres only; allowed with sample.shape.type = \"ellipsoid\": \"compaction\", \"growth\" or \"lattice\"");
  // A packing file brings its own grains: the grading of the run is the packing's.
  if (!c.sample.packing.empty()) c.sample.grading = lab::GradingConfig::ofPacking();
  if (c.sample.latticeJitter > 0.0 && c.sample.method != "lattice")
    fail("sample.lattice_jitter", fmt::format("{}", c.sample.latticeJitter), "applies to sample.method = \"lattice\" only");
  if (c.sample.method == "lattice") {
    const long n = c.sample.nParticles;
    const long side = std::lround(std::cbrt(static_cast<double>(n)));
    if (side * side * side != n)
      fail("sample.n_particles", std::to_string(n), "must be a cube n^3 (e.g. 512, 1000) for sample.method = \"lattice\"");
  }
  if (c.sample.shape.type == "ellipsoid" && c.sample.method == "loose-moment-free")
    fail("sample.method", "\"loose-moment-free\"", "is for spheres (contact moments off during compaction); "
         "ellipsoids: \"compaction\", \"growth\" or \"lattice\"");
  if (c.sample.shape.type == "ellipsoid" && c.sample.method == "compaction" && !c.sample.prepFrictionDeg)
    fail("sample.prep_friction_deg", "\"auto\"",
         "cannot search e0 for ellipsoids (their frictionless growth after compaction changes e); give an angle, "
         "or sample.method = \"growth\" or \"lattice\"");
  s.finish();

  Section ct(root, "contact");
  c.contact.model = ct.string("model", c.contact.model, {"kozicki", "rolling-linear", "hertz-mindlin"});
  const bool hertz = c.contact.hertz();
  c.contact.young = ct.number("young", c.contact.young, 1e3, 1e15, false, false, "must be in [1e3, 1e15] [Pa]");
  if (hertz) {
    c.contact.poisson = ct.number("poisson", c.contact.poisson, 0.0, 0.5, false, true,
                                  "must be in [0, 0.5) (Poisson's ratio of the grain material, contact.model = \"hertz-mindlin\")");
    if (c.sample.shape.type == "ellipsoid")
      fail("contact.model", "\"hertz-mindlin\"",
           "not available with sample.shape.type = \"ellipsoid\" (Hertz's law of two ellipsoids needs their local "
           "curvatures, which grainlab does not compute); allowed there: \"kozicki\", \"rolling-linear\"");
  } else {
    c.contact.poisson = ct.number("poisson", c.contact.poisson, 0.0, 1.0, false, false, "must be in [0, 1] (Ks = poisson * Kn)");
  }
  c.contact.shearModulus = ct.number("shear_modulus", c.contact.shearModulus, 1e3, 1e13, false, false,
                                     "must be in [1e3, 1e13] [Pa] (the grain material's shear modulus G)");
  c.contact.rolling = ct.string("rolling", c.contact.rolling, {"none", "kozicki", "rolling-linear"});
  c.contact.restitution = ct.number("restitution", c.contact.restitution, 0.0, 1.0, true, false,
                                    "must be in (0, 1] (normal coefficient of restitution; 1: no dashpot)");
  c.contact.frictionDeg = ct.number("friction_deg", c.contact.frictionDeg, 0.0, 90.0, false, true, "must be in [0, 90) [deg]");
  c.contact.beta = ct.number("beta", c.contact.beta, 0.0, 1e6, false, false, "must be >= 0");
  c.contact.eta = ct.number("eta", c.contact.eta, 0.0, 1e6, false, false, "must be >= 0");
  c.contact.wallFrictionDeg = ct.number("wall_friction_deg", c.contact.wallFrictionDeg, 0.0, 90.0, false, true, "must be in [0, 90) [deg]");
  c.contact.momentLimit = ct.string("moment_limit", c.contact.momentLimit, {"mean-radius", "yade"});
  if (ct.raw("kn"))
    c.contact.kn = ct.number("kn", 0.0, 1e-3, 1e15, false, false, "must be in [1e-3, 1e15] [N/m] (a constant normal stiffness)");
  const bool linear = c.contact.rollingSlot() == "rolling-linear";
  const toml::node* mu = ct.raw("rolling_friction");
  const toml::node* sph = ct.raw("sphericity");
  if (!linear && (mu || sph))
    fail(ct.path(mu ? "rolling_friction" : "sphericity"), show(mu ? *mu : *sph),
         "only used with the linear rolling resistance (contact.model = \"rolling-linear\", or \"hertz-mindlin\" "
         "with contact.rolling = \"rolling-linear\")");
  if (mu && sph) fail("contact.sphericity", show(*sph), "give either contact.rolling_friction or contact.sphericity, not both");
  c.contact.rollingFriction = ct.number("rolling_friction", c.contact.rollingFriction, 0.0, 10.0, false, false, "must be in [0, 10] (mu_r)");
  if (sph) {
    const std::string key = "contact.sphericity";
    if (!sph->is_table())
      fail(key, show(*sph), "must be an inline table { file = \"...\", c = 0.1963, k = ..., combine = \"min\" }");
    const toml::table& t = *sph->as_table();
    SphericityConfig sc;
    for (const auto& [k, v] : t) {
      const std::string name(k.str());
      if (name != "file" && name != "c" && name != "k" && name != "combine")
        fail(key + "." + name, show(v), "unknown key; allowed: file, c, k, combine");
    }
    const toml::node* file = t.get("file");
    if (!file || !file->is_string()) fail(key + ".file", file ? show(*file) : "(missing)", "a path to a CSV of sphericities is required");
    sc.file = resolvePath(file->value<std::string>().value(), baseDir);
    if (inputFilesMustExist && !pathExists(sc.file)) fail(key + ".file", show(*file), notFound(sc.file));
    if (inputFilesMustExist) sc.distribution = readSphericityFile(sc.file, key + ".file");  // not for resume
    if (const toml::node* cn = t.get("c")) {
      if (!cn->is_number() || !(numberOf(*cn) > 0.0) || !std::isfinite(numberOf(*cn)) || subnormal(numberOf(*cn)))
        fail(key + ".c", show(*cn), "must be a finite, normal number > 0 (mu_r = c psi^k)");
      sc.c = numberOf(*cn);
    }
    const toml::node* kn = t.get("k");
    if (!kn) fail(key + ".k", "(missing)", "the exponent k of mu_r = c psi^k has no default and must be given");
    if (!kn->is_number() || !std::isfinite(numberOf(*kn)) || subnormal(numberOf(*kn)))
      fail(key + ".k", show(*kn), "must be a finite, normal number (mu_r = c psi^k)");
    sc.k = numberOf(*kn);
    if (const toml::node* cb = t.get("combine")) {
      const std::string v = cb->is_string() ? cb->value<std::string>().value() : "";
      if (v != "min" && v != "mean" && v != "harmonic") fail(key + ".combine", show(*cb), "allowed: \"min\", \"mean\", \"harmonic\"");
      sc.combine = v;
    }
    c.contact.sphericity = sc;
  }
  ct.finish();

  Section t(root, "test");
  {
    std::vector<std::string> names;
    for (const lab::TestTypeInfo& i : lab::kTestTypes) names.emplace_back(i.name);
    const std::string type = t.string("type", std::string(lab::name(c.test.type)), names);
    c.test.type = *lab::parseTestType(type);  // one of names
  }
  c.test.boundary = t.string("boundary", c.test.boundary, {"walls", "periodic", "membrane"});
  c.test.aspectRatio = t.number("aspect_ratio", c.test.aspectRatio, 0.5, 4.0, false, false,
                                "must be in [0.5, 4] (height / diameter of the cylindrical sample)");
  c.test.membraneYoung = t.number("membrane_young", c.test.membraneYoung, 0.0, 1e10, false, false,
                                  "must be in [0, 1e10] [Pa] (Young modulus of the membrane; 0: the cell pressure alone)");
  c.test.membraneThickness = t.number("membrane_thickness", c.test.membraneThickness, 0.0, 1.0, true, false,
                                      "must be in (0, 1] [m] (thickness of the membrane)");
  c.test.membraneBinD50 = t.number("membrane_bin_d50", c.test.membraneBinD50, 0.5, 4.0, false, false,
                                   "must be in [0.5, 4] (side of the membrane's bins in d50)");
  if (t.raw("platen_friction_deg"))
    c.test.platenFrictionDeg = t.number("platen_friction_deg", 0.0, 0.0, 90.0, false, true, "must be in [0, 90) [deg]");
  if (c.test.boundary == "periodic" && c.sample.gravity)
    fail("sample.gravity", fmt::format("[{}, {}, {}]", (*c.sample.gravity)[0], (*c.sample.gravity)[1], (*c.sample.gravity)[2]),
         c.sample.method == "deposition" || c.sample.method == "under-compaction"
             ? fmt::format("sample.method = \"{}\" needs a floor (grains settle on the box's floor); allowed: "
                           "test.boundary = \"walls\"", c.sample.method)
             : std::string("not with test.boundary = \"periodic\" (a cell has no floor: gravity would accelerate the "
                           "whole sample); allowed: test.boundary = \"walls\""));
  if (lab::info(c.test.type).periodicOnly && c.test.boundary != "periodic")
    fail("test.type", fmt::format("\"{}\"", lab::name(c.test.type)),
         "needs test.boundary = \"periodic\" (a wall box has no shearing walls)");
  {
    const std::string drainage = t.string("drainage", "drained", {"drained", "undrained"});
    c.test.drainage = drainage == "undrained" ? lab::Drainage::Undrained : lab::Drainage::Drained;
  }
  c.test.confiningPressure = t.number("confining_pressure", c.test.confiningPressure, 1.0, 1e10, false, false, "must be in [1, 1e10] [Pa]");
  if (const toml::node* n = t.raw("axial_strain_rate")) {
    if (n->is_string() && n->value<std::string>().value() == "auto") {
      c.test.axialStrainRate.reset();
    } else {
      c.test.axialStrainRate = t.number("axial_strain_rate", 0.0, 0.0, 1e3, true, false,
                                        "must be \"auto\" or a rate > 0 [1/s]");
    }
  }
  c.test.finalAxialStrain = t.number("final_axial_strain", c.test.finalAxialStrain, 1e-4, 0.5, false, false, "must be in [1e-4, 0.5]");
  c.test.b = t.number("b", c.test.b, 0.0, 1.0, false, false, "must be in [0, 1] ((sigma2 - sigma3)/(sigma1 - sigma3))");
  if (const toml::node* n = t.raw("shear_strain_rate")) {
    if (n->is_string() && n->value<std::string>().value() == "auto") {
      c.test.shearStrainRate.reset();
    } else {
      c.test.shearStrainRate = t.number("shear_strain_rate", 0.0, 0.0, 1e3, true, false,
                                        "must be \"auto\" or a rate > 0 [1/s]");
    }
  }
  c.test.finalShearStrain = t.number("final_shear_strain", c.test.finalShearStrain, 1e-4, 2.0, false, false, "must be in [1e-4, 2]");
  if (const toml::node* n = t.raw("cs_window")) {
    if (n->is_string() && n->value<std::string>().value() == "auto") {
      c.test.csWindow.reset();
    } else {
      c.test.csWindow = t.number("cs_window", 0.0, 0.01, 1.0, false, false,
                                 "must be \"auto\" or a strain in [0.01, 1] (eps1, or gamma in simple shear)");
    }
  }
  c.test.probeStrain = t.number("probe_strain", c.test.probeStrain, 0.0, 1e-3, false, false,
                                "must be in [0, 1e-3] (axial strain of the small-strain probe; 0: no probe)");
  if (const toml::node* n = t.raw("unload_reload_at")) {
    const std::string key = t.path("unload_reload_at");
    c.test.unloadReloadAt = t.numbers(*n, key);
    if (c.test.type != lab::TestType::Triaxial)
      fail(key, show(*n), fmt::format("only for test.type = \"triaxial\" (here \"{}\")", lab::name(c.test.type)));
    for (std::size_t i = 0; i < c.test.unloadReloadAt.size(); ++i) {
      const double v = c.test.unloadReloadAt[i];
      if (!(v > 0.0) || !(v < c.test.finalAxialStrain))
        fail(key, show(*n), fmt::format("every axial strain must be in (0, {}) (below test.final_axial_strain)", c.test.finalAxialStrain));
      if (i > 0 && !(v > c.test.unloadReloadAt[i - 1]))
        fail(key, show(*n), "the axial strains must be strictly increasing");
    }
  }
  c.test.platenSlowdownUnbalanced =
      t.number("platen_slowdown_unbalanced", c.test.platenSlowdownUnbalanced, 0.0, 1.0, false, true,
               "must be in [0, 1) (unbalanced-force ratio above which the platens slow down; 0: off)");
  c.test.servoMaxSpeed = t.number("servo_max_speed", c.test.servoMaxSpeed, 0.0, 1e3, true, false,
                                  "must be in (0, 1000] [m/s] (servo speed cap while the test runs)");
  c.test.rateFollowsPressure = t.boolean("rate_follows_pressure", c.test.rateFollowsPressure);
  c.test.loopRest = t.boolean("loop_rest", c.test.loopRest);
  c.test.unloadToQFraction = t.number("unload_to_q_fraction", c.test.unloadToQFraction, 0.0, 1.0, false, true,
                                      "must be in [0, 1) (an unload ends at this fraction of the deviator at reversal)");
  c.test.maxAxialStress = t.number("max_axial_stress", c.test.maxAxialStress, 1.0, 1e10, false, false,
                                   "must be in [1, 1e10] [Pa] (the oedometer's loading ends there)");
  if (!(c.test.maxAxialStress > c.test.confiningPressure))
    fail("test.max_axial_stress", fmt::format("{}", c.test.maxAxialStress),
         fmt::format("must be above test.confining_pressure = {} (the oedometer loads from there)", c.test.confiningPressure));
  c.test.unloadAxialStress = t.number("unload_axial_stress", c.test.unloadAxialStress, 1.0, 1e10, false, false,
                                      "must be in [1, 1e10] [Pa] (the oedometer's unloading ends there)");
  if (!(c.test.unloadAxialStress < c.test.maxAxialStress))
    fail("test.unload_axial_stress", fmt::format("{}", c.test.unloadAxialStress),
         fmt::format("must be below test.max_axial_stress = {}", c.test.maxAxialStress));
  c.test.csr = t.number("csr", c.test.csr, 0.0, 2.0, true, false,
                        "must be in (0, 2] (cyclic stress ratio q_cyc / (2 p0))");
  c.test.nCycles = t.integer("n_cycles", c.test.nCycles, 1, 100'000);
  c.test.ruLimit = t.number("ru_limit", c.test.ruLimit, 0.0, 1.0, true, false,
                            "must be in (0, 1] (excess pore-pressure ratio ru = 1 - p'/p0 at liquefaction)");
  if (t.raw("back_pressure"))
    c.test.backPressure = t.number("back_pressure", 0.0, 0.0, 1e9, false, false,
                                   fmt::format("must be in [0, 1e9] [Pa] (the pore water's back pressure, gauge; it "
                                               "cavitates at u = -(back pressure + {:g} kPa))",
                                               (lab::TestConfig::kAtmosphericPressure - lab::TestConfig::kVapourPressure) / 1e3));
  c.test.liquefactionDaStrain = t.number("liquefaction_da_strain", c.test.liquefactionDaStrain, 0.0, 0.5, true, false,
                                         "must be in (0, 0.5] (double-amplitude axial strain at liquefaction)");
  if (const toml::node* n = t.raw("path")) parseStressPath(*n, baseDir, inputFilesMustExist, c.test);
  if (const toml::node* n = t.raw("shear_strain_amplitudes")) {
    const std::string key = t.path("shear_strain_amplitudes");
    c.test.shearStrainAmplitudes = t.numbers(*n, key);
    const auto& a = c.test.shearStrainAmplitudes;
    if (a.empty() || a.size() > static_cast<std::size_t>(lab::kMaxShearAmplitudes))
      fail(key, show(*n), fmt::format("must hold 1 to {} amplitudes", lab::kMaxShearAmplitudes));
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (!(a[i] >= 1e-7 && a[i] <= 0.1))
        fail(key, show(*n), "every amplitude must be a shear strain in [1e-7, 0.1]");
      if (i > 0 && !(a[i] > a[i - 1])) fail(key, show(*n), "the amplitudes must be strictly increasing");
    }
  }
  c.test.cyclesPerAmplitude = t.integer("cycles_per_amplitude", c.test.cyclesPerAmplitude, 1, 1000);
  if (c.test.type == lab::TestType::StressPath && c.test.path.empty() && c.test.pathSource.empty())
    fail("test.path", "(missing)",
         "test.type = \"stress-path\" needs its table: test.path = { file = \"path.csv\" } (docs/laboratory.md, "
         "\"Stress paths\")");
  t.finish();

  Section so(root, "solver");
  c.solver.damping = so.number("damping", c.solver.damping, 0.0, 1.0, false, true, "must be in [0, 1)");
  c.solver.viscousDamping = so.number("viscous_damping", c.solver.viscousDamping, 0.0, 1e9, false, false,
                                      "must be >= 0 [1/s] ([O]'s viscous damping; 0: local damping)");
  c.solver.dtFactor = so.number("dt_factor", c.solver.dtFactor, 0.0, 1.0, true, false, "must be in (0, 1] (fraction of the critical time step)");
  if (so.raw("dt"))
    c.solver.dt = so.number("dt", 0.0, 0.0, 1.0, true, false, "must be > 0 [s] (and at most the critical time step)");
  c.solver.forceDt = so.boolean("force_dt", c.solver.forceDt);
  c.solver.threads = static_cast<int>(so.integer("threads", c.solver.threads, 1, 1024));
  c.solver.unbalancedTolerance = so.number("unbalanced_tolerance", c.solver.unbalancedTolerance, 0.0, 1.0, true, false, "must be in (0, 1]");
  c.solver.stressTolerance = so.number("stress_tolerance", c.solver.stressTolerance, 0.0, 0.5, true, false, "must be in (0, 0.5]");
  c.solver.servoGain = so.number("servo_gain", c.solver.servoGain, 0.0, 1.0, true, false, "must be in (0, 1]");
  c.solver.servoIntegralSteps = so.number("servo_integral_steps", c.solver.servoIntegralSteps, 0.0, 1e9, false, false, "must be >= 0 [steps] (0 disables the integral term)");
  c.solver.servoMaxSpeed = so.number("servo_max_speed", c.solver.servoMaxSpeed, 0.0, 1e3, true, false, "must be > 0 [m/s]");
  c.solver.skinFraction = so.number("skin_fraction", c.solver.skinFraction, 0.0, 2.0, true, false, "must be in (0, 2]");
  c.solver.maxSteps = so.integer("max_steps", c.solver.maxSteps, 1, std::numeric_limits<std::int64_t>::max());
  so.finish();

  Section o(root, "output");
  c.output.dir = o.string("dir", c.output.dir, {});
  if (c.output.dir.empty()) fail("output.dir", "\"\"", "must be a non-empty path");
  c.output.recordEveryStrain = o.number("record_every_strain", c.output.recordEveryStrain, 1e-6, 0.1, false, false, "must be in [1e-6, 0.1]");
  c.output.plots = o.boolean("plots", c.output.plots);
  c.output.savePacking = o.boolean("save_packing", c.output.savePacking);
  c.output.checkpointEvery = o.number("checkpoint_every", c.output.checkpointEvery, 0.0, 1.0, false, false,
                                      "must be 0 or in [1e-4, 1] (axial strain between checkpoints; 0: none)");
  if (c.output.checkpointEvery > 0.0 && c.output.checkpointEvery < 1e-4)
    fail("output.checkpoint_every", fmt::format("{}", c.output.checkpointEvery), "must be 0 or in [1e-4, 1] (a checkpoint every step is no checkpoint)");
  c.output.vtkEveryStrain = o.number("vtk_every_strain", c.output.vtkEveryStrain, 0.0, 1.0, false, false,
                                     "must be 0 or in [1e-4, 1] (0: no VTK snapshots)");
  if (c.output.vtkEveryStrain > 0.0 && c.output.vtkEveryStrain < 1e-4)
    fail("output.vtk_every_strain", fmt::format("{}", c.output.vtkEveryStrain), "must be 0 or in [1e-4, 1] (at most 10 000 snapshots per unit strain)");
  c.output.microSnapshots = o.boolean("micro_snapshots", c.output.microSnapshots);
  c.output.bandFactor = o.number("band_factor", c.output.bandFactor, 1.0, 100.0, true, false,
                                 "must be in (1, 100] (a grain is in the shear band when its local shear strain "
                                 "is at least this times the box's)");
  c.output.bandStrainWindow = o.number("band_strain_window", c.output.bandStrainWindow, 0.0, 0.5, true, false,
                                       "must be in (0, 0.5] (the strain window, in the test's driving strain, "
                                       "whose increment the shear band is measured from)");
  o.finish();
  // Cross-key checks, after every key of every section is known and in range.
  if (c.sample.method == "lattice" && c.sample.packing.empty()) {
    const lab::GradingConfig& g = c.sample.grading;
    const double spread = g.type == "curve" ? g.diameters.back() / g.diameters.front() : g.type == "uniform" ? g.dMax / g.dMin : 1.0;
    if (spread > 1.01)
      fail("sample.grading", g.type == "curve" ? fmt::format("{{ type = \"curve\", {:g} to {:g} m }}", g.diameters.front(), g.diameters.back())
                                               : fmt::format("{{ type = \"uniform\", d_min = {:g}, d_max = {:g} }}", g.dMin, g.dMax),
           "sample.method = \"lattice\" places equal spheres (the grading's d50): allowed a grading of one size, d_max <= "
           "1.01 d_min, e.g. { type = \"uniform\", d_min = 2e-3, d_max = 2e-3 }");
  }
  if (c.test.boundary == "membrane") {
    // A cylinder in a membrane: an axisymmetric loading of spheres prepared by compaction.
    const lab::TestType tt = c.test.type;
    if (tt == lab::TestType::TrueTriaxial || tt == lab::TestType::Oedometer)
      fail("test.type", fmt::format("\"{}\"", lab::name(tt)),
           "not with test.boundary = \"membrane\" (a membrane holds one lateral stress and cannot stop the lateral "
           "strain); allowed there: \"isotropic\", \"triaxial\", \"constant-p\", \"cyclic-triaxial\", \"stress-path\"");
    for (const lab::PathPoint& pt : c.test.path)
      if (pt.control[0] != lab::PathControl::Stress || pt.control[1] != lab::PathControl::Stress || pt.value[0] != pt.value[1])
        fail("test.path", c.test.pathSource.empty() ? std::string("(inline)") : c.test.pathSource,
             "with test.boundary = \"membrane\" every point must give equal stresses for x and y (the membrane's one "
             "lateral stress); allowed: sigma_x = sigma_y targets, z a stress or a strain");
    if (!c.sample.packing.empty())
      fail("sample.packing", io::quotedPath(c.sample.packing),
           "not with test.boundary = \"membrane\" (a packing file holds a box or a cell); allowed: a sample prepared "
           "by sample.method = \"compaction\" or \"loose-moment-free\"");
    if (c.sample.method != "compaction" && c.sample.method != "loose-moment-free")
      fail("sample.method", fmt::format("\"{}\"", c.sample.method),
           "not with test.boundary = \"membrane\"; allowed: \"compaction\", \"loose-moment-free\"");
    if (c.sample.shape.type == "ellipsoid")
      fail("sample.shape.type", "\"ellipsoid\"", "not with test.boundary = \"membrane\" (its grains are spheres); "
           "allowed: \"sphere\"");
    if (c.sample.gravity)
      fail("sample.gravity", fmt::format("[{}, {}, {}]", (*c.sample.gravity)[0], (*c.sample.gravity)[1], (*c.sample.gravity)[2]),
           "not with test.boundary = \"membrane\" (no hydrostatic cell pressure); allowed: no gravity");
    // Frictionless spheres under a flexible membrane never come to rest: the bins' small pressure
    // differences keep them flowing (the reason preparation uses a rigid cylinder), so a test would
    // end in solver.max_steps instead of an equilibrium.
    if (c.contact.frictionDeg <= 0.0)
      fail("contact.friction_deg", fmt::format("{:g}", c.contact.frictionDeg),
           "must be > 0 with test.boundary = \"membrane\" (frictionless spheres flow under a flexible membrane and "
           "never reach equilibrium); allowed: (0, 90) [deg], or test.boundary = \"walls\"");
  }
  refuseInapplicable(root, c);
  return c;
}

toml::table resolvedTable(const lab::RunConfig& c) {
  // Only the keys that apply (inapplicable(): the others are refused in a config), so that the
  // resolved config is itself a valid config and records what ran.
  auto put = [&c](toml::table& t, const std::string& section, const char* key, auto&& value) {
    if (inapplicable(c, section + "." + key).empty()) t.insert(key, std::forward<decltype(value)>(value));
  };
  toml::table grading;
  grading.insert("type", c.sample.grading.type);
  if (c.sample.grading.type == "curve") {
    toml::array d, p;
    for (double v : c.sample.grading.diameters) d.push_back(v);
    for (double v : c.sample.grading.passing) p.push_back(v);
    grading.insert("diameters", d);
    grading.insert("passing", p);
  } else if (c.sample.grading.type == "uniform") {
    grading.insert("d_min", c.sample.grading.dMin);
    grading.insert("d_max", c.sample.grading.dMax);
  } else if (c.sample.grading.type == "list") {
    grading.insert("file", c.sample.grading.file);
  }
  toml::table shape{{"type", c.sample.shape.type}};
  for (const auto& [k, v] : {std::pair<const char*, double>{"elongation", c.sample.shape.elongation},
                             {"flatness", c.sample.shape.flatness},
                             {"fraction", c.sample.shape.fraction},
                             {"eccentricity_step", c.sample.shape.eccentricityStep}})
    put(shape, "sample.shape", k, v);
  put(shape, "sample.shape", "orientation", c.sample.shape.orientation);
  toml::table sample{{"n_particles", c.sample.nParticles},
                     {"grading", grading},
                     {"density", c.sample.density},
                     {"seed", static_cast<std::int64_t>(c.sample.seed)},
                     {"packing", c.sample.packing}};
  put(sample, "sample", "e0", c.sample.e0);
  put(sample, "sample", "e0_tolerance", c.sample.e0Tolerance);
  put(sample, "sample", "initial_void_ratio", c.sample.initialVoidRatio);
  put(sample, "sample", "prep_stiffness_factor", c.sample.prepStiffnessFactor);
  put(sample, "sample", "prep_damping", c.sample.prepDamping);
  put(sample, "sample", "prep_ramp_steps", static_cast<std::int64_t>(c.sample.prepRampSteps));
  put(sample, "sample", "method", c.sample.method);
  put(sample, "sample", "growth_rate", c.sample.growthRate);
  put(sample, "sample", "lattice_jitter", c.sample.latticeJitter);
  put(sample, "sample", "drop_height", c.sample.dropHeight);
  put(sample, "sample", "layers", static_cast<std::int64_t>(c.sample.layers));
  put(sample, "sample", "under_compaction", c.sample.underCompaction);
  if (c.sample.gravity) put(sample, "sample", "gravity", toml::array{(*c.sample.gravity)[0], (*c.sample.gravity)[1], (*c.sample.gravity)[2]});
  put(sample, "sample", "shape", shape);
  if (c.sample.packingFrictionDeg) put(sample, "sample", "packing_friction_deg", *c.sample.packingFrictionDeg);
  if (c.sample.prepFrictionDeg) put(sample, "sample", "prep_friction_deg", *c.sample.prepFrictionDeg);
  else put(sample, "sample", "prep_friction_deg", "auto");
  toml::table contact{{"model", c.contact.model},
                      {"poisson", c.contact.poisson},
                      {"friction_deg", c.contact.frictionDeg}};
  put(contact, "contact", "young", c.contact.young);
  put(contact, "contact", "shear_modulus", c.contact.shearModulus);
  put(contact, "contact", "rolling", c.contact.rolling);
  put(contact, "contact", "restitution", c.contact.restitution);
  put(contact, "contact", "beta", c.contact.beta);
  put(contact, "contact", "eta", c.contact.eta);
  put(contact, "contact", "wall_friction_deg", c.contact.wallFrictionDeg);
  put(contact, "contact", "moment_limit", c.contact.momentLimit);
  if (c.contact.kn) contact.insert("kn", *c.contact.kn);
  if (c.contact.sphericity) {
    const auto& sc = *c.contact.sphericity;
    put(contact, "contact", "sphericity", toml::table{{"file", sc.file}, {"c", sc.c}, {"k", sc.k}, {"combine", sc.combine}});
  } else {
    put(contact, "contact", "rolling_friction", c.contact.rollingFriction);
  }
  toml::table test{{"type", std::string(lab::name(c.test.type))},
                   {"boundary", c.test.boundary},
                   {"confining_pressure", c.test.confiningPressure},
                   {"probe_strain", c.test.probeStrain}};
  put(test, "test", "final_axial_strain", c.test.finalAxialStrain);
  put(test, "test", "aspect_ratio", c.test.aspectRatio);
  put(test, "test", "membrane_young", c.test.membraneYoung);
  put(test, "test", "membrane_thickness", c.test.membraneThickness);
  put(test, "test", "membrane_bin_d50", c.test.membraneBinD50);
  if (c.test.platenFrictionDeg) put(test, "test", "platen_friction_deg", *c.test.platenFrictionDeg);
  put(test, "test", "b", c.test.b);
  put(test, "test", "final_shear_strain", c.test.finalShearStrain);
  if (c.test.axialStrainRate) put(test, "test", "axial_strain_rate", *c.test.axialStrainRate);
  else put(test, "test", "axial_strain_rate", "auto");
  if (!c.test.unloadReloadAt.empty()) {
    toml::array at;
    for (double v : c.test.unloadReloadAt) at.push_back(v);
    test.insert("unload_reload_at", at);
  }
  put(test, "test", "unload_to_q_fraction", c.test.unloadToQFraction);
  put(test, "test", "loop_rest", c.test.loopRest);
  put(test, "test", "platen_slowdown_unbalanced", c.test.platenSlowdownUnbalanced);
  put(test, "test", "rate_follows_pressure", c.test.rateFollowsPressure);
  put(test, "test", "servo_max_speed", c.test.servoMaxSpeed);
  if (c.test.csWindow) put(test, "test", "cs_window", *c.test.csWindow);
  else put(test, "test", "cs_window", "auto");
  if (c.test.shearStrainRate) put(test, "test", "shear_strain_rate", *c.test.shearStrainRate);
  else put(test, "test", "shear_strain_rate", "auto");
  put(test, "test", "drainage", c.test.drainage == lab::Drainage::Undrained ? "undrained" : "drained");
  put(test, "test", "max_axial_stress", c.test.maxAxialStress);
  put(test, "test", "unload_axial_stress", c.test.unloadAxialStress);
  put(test, "test", "csr", c.test.csr);
  put(test, "test", "n_cycles", c.test.nCycles);
  put(test, "test", "ru_limit", c.test.ruLimit);
  if (c.test.backPressure) put(test, "test", "back_pressure", *c.test.backPressure);
  put(test, "test", "liquefaction_da_strain", c.test.liquefactionDaStrain);
  {
    toml::array amplitudes;
    for (double v : c.test.shearStrainAmplitudes) amplitudes.push_back(v);
    put(test, "test", "shear_strain_amplitudes", amplitudes);
  }
  put(test, "test", "cycles_per_amplitude", c.test.cyclesPerAmplitude);
  if (!c.test.path.empty()) {
    toml::array points, controls;
    for (const lab::PathPoint& p : c.test.path) {
      points.push_back(toml::array{p.s, p.value[0], p.value[1], p.value[2]});
      controls.push_back(toml::array{std::string(lab::controlName(p.control[0])), std::string(lab::controlName(p.control[1])),
                                     std::string(lab::controlName(p.control[2]))});
    }
    toml::table path{{"points", points}, {"controls", controls}};
    if (!c.test.pathSource.empty()) path.insert("source", c.test.pathSource);
    put(test, "test", "path", path);
  }
  toml::table solver{{"viscous_damping", c.solver.viscousDamping},
                     {"dt_factor", c.solver.dtFactor},
                     {"threads", c.solver.threads},
                     {"unbalanced_tolerance", c.solver.unbalancedTolerance},
                     {"stress_tolerance", c.solver.stressTolerance},
                     {"servo_gain", c.solver.servoGain},
                     {"servo_integral_steps", c.solver.servoIntegralSteps},
                     {"servo_max_speed", c.solver.servoMaxSpeed},
                     {"skin_fraction", c.solver.skinFraction},
                     {"max_steps", static_cast<std::int64_t>(c.solver.maxSteps)}};
  put(solver, "solver", "damping", c.solver.damping);
  put(solver, "solver", "force_dt", c.solver.forceDt);
  if (c.solver.dt) solver.insert("dt", *c.solver.dt);
  toml::table output{{"dir", c.output.dir},
                     {"plots", c.output.plots},
                     {"save_packing", c.output.savePacking},
                     {"vtk_every_strain", c.output.vtkEveryStrain}};
  put(output, "output", "record_every_strain", c.output.recordEveryStrain);
  put(output, "output", "micro_snapshots", c.output.microSnapshots);
  put(output, "output", "checkpoint_every", c.output.checkpointEvery);
  put(output, "output", "band_factor", c.output.bandFactor);
  put(output, "output", "band_strain_window", c.output.bandStrainWindow);
  return toml::table{{"sample", sample}, {"contact", contact}, {"test", test},
                     {"solver", solver}, {"output", output}};
}

std::string toTomlString(const toml::table& table) {
  std::ostringstream os;
  os << table << "\n";
  return os.str();
}

}  // namespace grainlab::io

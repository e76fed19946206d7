// `grainlab calibrate CONFIG --target TARGET.toml`: fits micro-parameters of CONFIG to laboratory
// values and curves (docs/calibration.md). This command validates the config and the target file
// (bad input: exit 2 naming the key, the value and what is allowed), writes the calibration
// folder's calibration.json -- the inputs with every default filled in, which a restart compares
// against so that a folder is never resumed with other inputs -- and then becomes the Python driver
// tools/calibrate.py (execv, an argument vector), which runs the optimiser and the `grainlab run`s.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <thread>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/study_folder.hpp"
#include "cli/sweep_dask.hpp"
#include "io/install_paths.hpp"
#include "core/errors.hpp"
#include "io/config.hpp"
#include "io/results.hpp"

namespace grainlab::cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The optimisers of NLopt offered (tools/calibrate.py maps them; docs/calibration.md says why).
const std::vector<std::string> kAlgorithms{"bobyqa", "cobyla", "neldermead", "sbplx", "direct", "crs2"};
// Curve columns a laboratory file may give besides eps1 (docs/physics.md §1 signs: eps_v > 0 in contraction).
const std::vector<std::string> kCurveQuantities{"q", "sigma1_over_sigma3", "eps_v"};
constexpr std::uintmax_t kMaxCurveBytes = 16u << 20;
constexpr std::size_t kMaxCurveRows = 100000;

// A value or path for a message, within 80 characters: a long one keeps its start and its end
// (a path's file name, which says which file is meant) around "...".
std::string cutMiddle(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s.size() > 80 ? s.substr(0, 38) + "..." + s.substr(s.size() - 39) : s;
}

std::string show(const toml::node& node) {
  std::ostringstream os;
  node.visit([&](const auto& v) { os << v; });
  return os.str();
}

std::string quoted(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "\"" : ", \"") + n + "\"";
  return s;
}

[[noreturn]] void bad(const std::string& where, const std::string& value, const std::string& allowed) {
  throw InputError(fmt::format("target error: {} = {}: {}", where, cutMiddle(value), allowed));
}

// One table of the target file: typed getters. A misspelt key is an error, not silently ignored,
// and is reported before anything else about the table (e.g. before "min is required" for "mn").
class Table {
 public:
  Table(const toml::table* table, std::string name, const std::vector<std::string>& known)
      : table_(table), name_(std::move(name)) {
    if (!table_) return;
    for (const auto& [k, v] : *table_)
      if (std::find(known.begin(), known.end(), std::string(k.str())) == known.end())
        bad(path(std::string(k.str())), show(v), "unknown key; allowed: " + quoted(known));
  }
  std::string path(const std::string& key) const { return name_ + "." + key; }

  const toml::node* raw(const std::string& key) const { return table_ ? table_->get(key) : nullptr; }
  std::optional<double> number(const std::string& key, double lo, double hi, bool loOpen, const std::string& allowed) {
    const toml::node* n = raw(key);
    if (!n) return std::nullopt;
    if (!n->is_number()) bad(path(key), show(*n), "must be a number; " + allowed);
    const double v = n->value<double>().value();
    if (!std::isfinite(v) || (loOpen ? v <= lo : v < lo) || v > hi) bad(path(key), show(*n), allowed);
    return v;
  }
  std::optional<long> integer(const std::string& key, long lo, long hi) {
    const toml::node* n = raw(key);
    if (!n) return std::nullopt;
    const std::string allowed = fmt::format("must be an integer in [{}, {}]", lo, hi);
    if (!n->is_integer()) bad(path(key), show(*n), allowed);
    const long v = static_cast<long>(n->value<std::int64_t>().value());
    if (v < lo || v > hi) bad(path(key), show(*n), allowed);
    return v;
  }
  std::optional<bool> boolean(const std::string& key) {
    const toml::node* n = raw(key);
    if (!n) return std::nullopt;
    if (!n->is_boolean()) bad(path(key), show(*n), "must be true or false");
    return n->value<bool>().value();
  }
  std::optional<std::string> string(const std::string& key, const std::vector<std::string>& allowed = {}) {
    const toml::node* n = raw(key);
    if (!n) return std::nullopt;
    const std::string choices = allowed.empty() ? "must be a string" : "allowed: " + quoted(allowed);
    if (!n->is_string()) bad(path(key), show(*n), choices);
    std::string v = n->value<std::string>().value();
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), v) == allowed.end())
      bad(path(key), show(*n), choices);
    return v;
  }

 private:
  const toml::table* table_;
  std::string name_;
};

const toml::table* subTable(const toml::table& root, const std::string& name) {
  const toml::node* n = root.get(name);
  if (n && !n->is_table()) bad(name, show(*n), "must be a table [" + name + "]");
  return n ? n->as_table() : nullptr;
}

// [[name]]: an array of tables.
std::vector<const toml::table*> tableArray(const toml::table& root, const std::string& name) {
  std::vector<const toml::table*> out;
  const toml::node* n = root.get(name);
  if (!n) return out;
  if (!n->is_array_of_tables()) bad(name, show(*n), "must be an array of tables [[" + name + "]]");
  for (const auto& e : *n->as_array()) out.push_back(e.as_table());
  return out;
}

std::string formatValue(double v) { return fmt::format("{}", v); }

// A free parameter's value must be one the config accepts and that reaches the run: the config
// with KEY = value is parsed, and its resolved form must carry that floating-point value.
void checkParameterValue(const toml::table& base, const std::string& baseDir, const std::string& key,
                         const std::string& what, double value) {
  toml::table t = base;
  io::applyOverride(t, key + "=" + formatValue(value));
  lab::RunConfig parsed;
  try {
    parsed = io::parseConfig(t, baseDir);
  } catch (const InputError& e) {
    throw InputError(fmt::format("target error: parameter \"{}\" {} = {}: not accepted by the config ({})", key,
                                 what, formatValue(value), e.what()));
  }
  const toml::table resolved = io::resolvedTable(parsed);
  const auto node = resolved.at_path(key);
  if (!node || !node.is_floating_point() || node.value<double>().value() != value)
    bad(fmt::format("parameter \"{}\".key", key), key,
        "not a continuous (floating-point) key that this config uses; `grainlab check CONFIG` lists them");
}

json parseParameters(const toml::table& root, const toml::table& base, const std::string& baseDir) {
  json out = json::array();
  std::set<std::string> seen;
  const auto tables = tableArray(root, "parameter");
  if (tables.empty()) bad("parameter", "(none)", "give at least one [[parameter]] with key, min, max");
  for (std::size_t i = 0; i < tables.size(); ++i) {
    const std::string where = fmt::format("parameter[{}].key", i + 1);
    const toml::node* keyNode = tables[i]->get("key");
    if (!keyNode || !keyNode->is_string())
      bad(where, keyNode ? show(*keyNode) : "(missing)", "a dotted config key, e.g. \"contact.friction_deg\"");
    const std::string key = keyNode->value<std::string>().value();
    if (key == "sample.seed") bad(where, key, "seeds are set by [evaluation] seeds, not calibrated");
    if (!seen.insert(key).second) bad(where, key, "each parameter once");
    // Messages name the parameter by its key from here on.
    Table p(tables[i], fmt::format("parameter \"{}\"", key), {"key", "min", "max", "start", "log"});
    const auto lo = p.number("min", -1e300, 1e300, false, "a finite number");
    const auto hi = p.number("max", -1e300, 1e300, false, "a finite number");
    if (!lo) bad(p.path("min"), "(missing)", "the lower bound is required");
    if (!hi) bad(p.path("max"), "(missing)", "the upper bound is required");
    if (!(*hi > *lo)) bad(p.path("max"), formatValue(*hi), fmt::format("must be > min = {}", formatValue(*lo)));
    const bool log = p.boolean("log").value_or(false);
    if (log && *lo <= 0.0) bad(p.path("min"), formatValue(*lo), "must be > 0 with log = true");
    const double start = p.number("start", *lo, *hi, false, fmt::format("within [min, max] = [{}, {}]",
                                                                        formatValue(*lo), formatValue(*hi)))
                             .value_or(log ? std::sqrt(*lo * *hi) : 0.5 * (*lo + *hi));
    checkParameterValue(base, baseDir, key, "min", *lo);
    checkParameterValue(base, baseDir, key, "max", *hi);
    checkParameterValue(base, baseDir, key, "start", start);
    out.push_back({{"key", key}, {"min", *lo}, {"max", *hi}, {"start", start}, {"log", log}});
  }
  return out;
}

// The pressure a target or a curve belongs to: its confining_pressure, or the config's. Checked
// against what the config accepts (parsed with test.confining_pressure = value).
double parsePressure(Table& t, const toml::table& base, const std::string& baseDir, double configPressure) {
  const auto p = t.number("confining_pressure", 0.0, 1e10, true, "must be in (0, 1e10] [Pa] (the test's test.confining_pressure)");
  if (!p) return configPressure;
  toml::table c = base;
  io::applyOverride(c, "test.confining_pressure=" + formatValue(*p));
  try {
    (void)io::parseConfig(c, baseDir);
  } catch (const InputError& e) {
    bad(t.path("confining_pressure"), formatValue(*p), fmt::format("not accepted by the config ({})", e.what()));
  }
  return *p;
}

json parseTargets(const toml::table& root, const toml::table& base, const std::string& baseDir, double configPressure) {
  json out = json::array();
  std::set<std::pair<std::string, double>> seen;
  const auto tables = tableArray(root, "target");
  for (std::size_t i = 0; i < tables.size(); ++i) {
    Table t(tables[i], fmt::format("target[{}]", i + 1), {"key", "value", "weight", "scale", "confining_pressure"});
    const auto key = t.string("key");
    if (!key || key->empty() || key->find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.") !=
                                    std::string::npos)
      bad(t.path("key"), key.value_or("(missing)"), "a numeric key of summary.json, e.g. \"phi_peak_deg\" (letters, digits, _ and . for nested keys)");
    const double pressure = parsePressure(t, base, baseDir, configPressure);
    if (!seen.insert({*key, pressure}).second)
      bad(t.path("key"), *key, fmt::format("each target key once per confining_pressure (here {} Pa)", formatValue(pressure)));
    const auto value = t.number("value", -1e300, 1e300, false, "a finite number");
    if (!value) bad(t.path("value"), "(missing)", "the measured value is required");
    const double weight = t.number("weight", 0.0, 1e12, true, "must be > 0").value_or(1.0);
    const auto scale = t.number("scale", 0.0, 1e300, true, "must be > 0 (the residual's unit)");
    if (!scale && *value == 0.0) bad(t.path("scale"), "(missing)", "required when value = 0 (default scale: |value|)");
    out.push_back({{"key", *key}, {"summary_key", *key}, {"confining_pressure", pressure}, {"value", *value},
                   {"weight", weight}, {"scale", scale.value_or(std::abs(*value))}});
  }
  return out;
}

// The laboratory curve: CSV with a header; eps1 and any of q, sigma1_over_sigma3, eps_v.
std::map<std::string, std::vector<double>> readCurveCsv(const fs::path& file, const std::string& where) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) bad(where, file.string(), "not a readable regular file");
  if (fs::file_size(file, ec) > kMaxCurveBytes)
    bad(where, file.string(), fmt::format("larger than the {} MiB allowed", kMaxCurveBytes >> 20));
  std::ifstream in(file);
  std::string line;
  std::vector<std::string> header;
  std::map<std::string, std::vector<double>> columns;
  std::size_t lineNo = 0;
  auto split = [](const std::string& s) {
    std::vector<std::string> cells;
    std::stringstream ss(s);
    std::string cell;
    while (std::getline(ss, cell, ',')) {
      const auto b = cell.find_first_not_of(" \t\r");
      const auto e = cell.find_last_not_of(" \t\r");
      cells.push_back(b == std::string::npos ? std::string() : cell.substr(b, e - b + 1));
    }
    return cells;
  };
  while (std::getline(in, line)) {
    ++lineNo;
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    std::vector<std::string> cells = split(line);
    if (header.empty()) {
      header = cells;
      if (std::find(header.begin(), header.end(), "eps1") == header.end())
        bad(fmt::format("{} ({}) header", where, file.string()), line, "needs a column eps1 and any of " + quoted(kCurveQuantities));
      continue;
    }
    if (cells.size() != header.size())
      bad(fmt::format("{} ({}) line {}", where, file.string(), lineNo), line,
          fmt::format("{} cells, the header has {}", cells.size(), header.size()));
    for (std::size_t c = 0; c < header.size(); ++c) {
      if (header[c] != "eps1" && std::find(kCurveQuantities.begin(), kCurveQuantities.end(), header[c]) == kCurveQuantities.end())
        continue;  // other columns of a laboratory file are not used
      char* end = nullptr;
      errno = 0;
      const double v = std::strtod(cells[c].c_str(), &end);
      if (cells[c].empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
        bad(fmt::format("{} ({}) line {} column {}", where, file.string(), lineNo, header[c]), cells[c],
            "must be a finite number");
      columns[header[c]].push_back(v);
    }
    if (columns["eps1"].size() > kMaxCurveRows) bad(where, file.string(), fmt::format("more than {} rows", kMaxCurveRows));
  }
  const auto& eps1 = columns["eps1"];
  if (eps1.size() < 3) bad(where, file.string(), "needs at least 3 data rows");
  for (std::size_t i = 1; i < eps1.size(); ++i)
    if (!(eps1[i] > eps1[i - 1]))
      bad(fmt::format("{} ({}) eps1 of data row {}", where, file.string(), i + 1), fmt::format("{} after {}", eps1[i], eps1[i - 1]),
          "eps1 must increase strictly (one loading branch; compared on a common eps1 grid)");
  return columns;
}

json parseCurve(const toml::table* table, const std::string& name, const fs::path& targetDir, double finalAxialStrain,
               const toml::table& base, const std::string& baseDir, double configPressure) {
  Table t(table, name, {"file", "quantities", "q_unit", "strain_unit", "eps1_min", "eps1_max", "points", "weight", "scale",
                        "confining_pressure"});
  const double pressure = parsePressure(t, base, baseDir, configPressure);
  const auto file = t.string("file");
  if (!file) bad(t.path("file"), "(missing)", "a CSV file (relative to the target file)");
  const fs::path path = fs::absolute(fs::path(*file).is_absolute() ? fs::path(*file) : targetDir / *file);
  const std::string qUnit = t.string("q_unit", {"Pa", "kPa", "MPa"}).value_or("Pa");
  const std::string strainUnit = t.string("strain_unit", {"1", "percent"}).value_or("1");
  auto columns = readCurveCsv(path, t.path("file"));
  const double strainFactor = strainUnit == "percent" ? 0.01 : 1.0;
  const double qFactor = qUnit == "kPa" ? 1e3 : qUnit == "MPa" ? 1e6 : 1.0;
  for (double& v : columns["eps1"]) v *= strainFactor;
  if (columns.count("eps_v"))
    for (double& v : columns["eps_v"]) v *= strainFactor;
  if (columns.count("q"))
    for (double& v : columns["q"]) v *= qFactor;

  std::vector<std::string> quantities;
  if (const toml::node* n = t.raw("quantities")) {
    if (!n->is_array() || n->as_array()->empty()) bad(t.path("quantities"), show(*n), "a non-empty array out of " + quoted(kCurveQuantities));
    for (const auto& e : *n->as_array()) {
      const std::string q = e.value<std::string>().value_or("");
      if (std::find(kCurveQuantities.begin(), kCurveQuantities.end(), q) == kCurveQuantities.end())
        bad(t.path("quantities"), show(*n), "allowed entries: " + quoted(kCurveQuantities));
      if (!columns.count(q)) bad(t.path("quantities"), q, "no such column in " + path.string());
      quantities.push_back(q);
    }
  } else {
    for (const auto& q : kCurveQuantities)
      if (columns.count(q)) quantities.push_back(q);
    if (quantities.empty()) bad(t.path("file"), path.string(), "needs a column out of " + quoted(kCurveQuantities));
  }
  // Per-quantity weights and scales: one number for all, or an inline table by quantity.
  auto perQuantity = [&](const std::string& key, const std::string& allowed) {
    std::map<std::string, double> values;
    const toml::node* n = t.raw(key);
    if (!n) return values;
    auto check = [&](const toml::node& v, const std::string& where) {
      const std::optional<double> d = v.value<double>();
      if (!v.is_number() || !d || !std::isfinite(*d) || *d <= 0.0) bad(where, show(v), allowed);
      return *d;
    };
    if (n->is_table()) {
      for (const auto& [k, v] : *n->as_table()) {
        const std::string q(k.str());
        if (std::find(quantities.begin(), quantities.end(), q) == quantities.end())
          bad(t.path(key) + "." + q, show(v), "not a compared quantity; compared: " + quoted(quantities));
        values[q] = check(v, t.path(key) + "." + q);
      }
    } else {
      const double d = check(*n, t.path(key));
      for (const auto& q : quantities) values[q] = d;
    }
    return values;
  };
  const auto weights = perQuantity("weight", "must be > 0 (a number, or { q = 1.0, eps_v = 0.5 })");
  const auto scales = perQuantity("scale", "must be > 0 in SI units (a number, or { q = 2e5, eps_v = 0.02 })");

  // The comparison grid, given in the file's strain unit; by default the part of the laboratory
  // curve that the run reaches.
  const auto& eps1 = columns["eps1"];
  const std::string strainRange = strainUnit == "percent" ? "an axial strain in percent, in [0, 100]" : "an axial strain in [0, 1]";
  const double lo = t.number("eps1_min", 0.0, 1.0 / strainFactor, false, strainRange)
                        .value_or(std::max(0.0, eps1.front()) / strainFactor) * strainFactor;
  const double hi = t.number("eps1_max", 0.0, 1.0 / strainFactor, true, strainRange)
                        .value_or(std::min(eps1.back(), finalAxialStrain) / strainFactor) * strainFactor;
  const long points = t.integer("points", 2, 10000).value_or(50);
  if (lo < eps1.front() || hi > eps1.back() || !(hi > lo))
    bad(name + ".eps1_min/eps1_max", fmt::format("[{}, {}]", lo, hi),
        fmt::format("the grid must lie within the file's eps1 range [{}, {}]", eps1.front(), eps1.back()));
  if (hi > finalAxialStrain)
    bad(t.path("eps1_max"), formatValue(hi),
        fmt::format("beyond the run's test.final_axial_strain = {}", formatValue(finalAxialStrain)));

  json qs = json::array();
  for (const auto& q : quantities) {
    // Default scale: the laboratory curve's own magnitude (peak q, peak stress-ratio excess over 1,
    // largest |eps_v|), so each quantity's misfit is a fraction of what was measured.
    double scale = 0.0;
    for (double v : columns[q]) scale = std::max(scale, std::abs(q == "sigma1_over_sigma3" ? v - 1.0 : v));
    if (scales.count(q)) scale = scales.at(q);
    if (!(scale > 0.0)) bad(t.path("scale." + q), "(default 0)", "the curve is zero throughout: give " + t.path("scale"));
    qs.push_back({{"name", q}, {"weight", weights.count(q) ? weights.at(q) : 1.0}, {"scale", scale}});
  }
  json data;
  data["eps1"] = eps1;
  for (const auto& q : quantities) data[q] = columns[q];
  return {{"file", path.string()}, {"q_unit", qUnit}, {"strain_unit", strainUnit}, {"quantities", qs},
          {"eps1_min", lo}, {"eps1_max", hi}, {"points", points}, {"data", data}, {"confining_pressure", pressure}};
}

// [curve] (one table) or [[curve]] (one per confining_pressure).
json parseCurves(const toml::table& root, const fs::path& targetDir, double finalAxialStrain, const toml::table& base,
                 const std::string& baseDir, double configPressure) {
  json out = json::array();
  const toml::node* n = root.get("curve");
  if (!n) return out;
  if (n->is_table()) {
    out.push_back(parseCurve(n->as_table(), "curve", targetDir, finalAxialStrain, base, baseDir, configPressure));
    return out;
  }
  if (!n->is_array_of_tables())
    bad("curve", show(*n), "must be a table [curve], or an array of tables [[curve]] (one per confining_pressure)");
  std::set<double> pressures;
  std::size_t i = 0;
  for (const auto& e : *n->as_array()) {
    const std::string name = fmt::format("curve[{}]", ++i);
    json c = parseCurve(e.as_table(), name, targetDir, finalAxialStrain, base, baseDir, configPressure);
    if (!pressures.insert(c["confining_pressure"].get<double>()).second)
      bad(name + ".confining_pressure", formatValue(c["confining_pressure"].get<double>()),
          "one curve per confining_pressure (the default is the config's test.confining_pressure)");
    out.push_back(std::move(c));
  }
  return out;
}

// The test conditions the targets and curves need: one run per condition and seed for each
// evaluation. A file that names no other pressure than the config's has one condition with an
// empty id (run names and outputs as before there were several); otherwise every pressure is a
// condition "p<kPa>kPa" whose runs get test.confining_pressure, and every target and curve
// quantity is labelled with its pressure ("phi_peak_deg@100kPa", "q@100kPa").
json assignConditions(json& target, double configPressure) {
  std::set<double> pressures;
  for (const auto& t : target["targets"]) pressures.insert(t["confining_pressure"].get<double>());
  for (const auto& c : target["curves"]) pressures.insert(c["confining_pressure"].get<double>());
  const bool single = pressures.empty() || (pressures.size() == 1 && *pressures.begin() == configPressure);
  json conditions = json::array();
  auto idOf = [&](double p) { return single ? std::string() : fmt::format("p{:g}kPa", p / 1e3); };
  auto suffix = [&](double p) { return single ? std::string() : fmt::format("@{:g}kPa", p / 1e3); };
  if (single) {
    conditions.push_back({{"id", ""}, {"confining_pressure", configPressure}, {"sets", json::array()}});
  } else {
    std::set<std::string> ids;
    for (double p : pressures) {
      if (!ids.insert(idOf(p)).second)
        bad("confining_pressure", formatValue(p), "pressures must differ in their first 6 digits (in kPa)");
      conditions.push_back({{"id", idOf(p)}, {"confining_pressure", p},
                            {"sets", json::array({"test.confining_pressure=" + formatValue(p)})}});
    }
  }
  for (auto& t : target["targets"]) {
    const double p = t["confining_pressure"].get<double>();
    t["condition"] = idOf(p);
    t["key"] = t["summary_key"].get<std::string>() + suffix(p);
  }
  for (auto& c : target["curves"]) {
    const double p = c["confining_pressure"].get<double>();
    c["condition"] = idOf(p);
    c["label"] = "curve" + suffix(p);
    for (auto& q : c["quantities"]) q["label"] = q["name"].get<std::string>() + suffix(p);
  }
  return conditions;
}

json parseSeeds(const toml::table& root, long configSeed) {
  Table t(subTable(root, "evaluation"), "evaluation", {"seeds"});
  json seeds = json::array();
  const toml::node* n = t.raw("seeds");
  if (!n) {
    for (long s = 0; s < 3; ++s) seeds.push_back(configSeed + s);
  } else if (n->is_integer()) {
    const long count = t.integer("seeds", 1, 1000).value();
    for (long s = 0; s < count; ++s) seeds.push_back(configSeed + s);
  } else if (n->is_array() && !n->as_array()->empty() && n->as_array()->size() <= 1000) {
    std::set<long> unique;
    for (const auto& e : *n->as_array()) {
      const auto v = e.value<std::int64_t>();
      if (!e.is_integer() || *v < 0 || !unique.insert(*v).second)
        bad(t.path("seeds"), show(*n), "distinct integers >= 0, e.g. [1, 2, 3], or a count");
      seeds.push_back(*v);
    }
  } else {
    bad(t.path("seeds"), show(*n), "an array of 1-1000 distinct integers >= 0 (e.g. [1, 2, 3]) or a count");
  }
  return seeds;
}

json parseOptimizer(const toml::table& root) {
  Table t(subTable(root, "optimizer"), "optimizer",
          {"algorithm", "max_evaluations", "initial_step", "xtol", "stop_objective", "seed"});
  json o;
  o["algorithm"] = t.string("algorithm", kAlgorithms).value_or("bobyqa");
  o["max_evaluations"] = t.integer("max_evaluations", 1, 100000).value_or(40);
  o["initial_step"] = t.number("initial_step", 0.0, 1.0, true, "in (0, 1]: a fraction of each parameter's range").value_or(0.25);
  o["xtol"] = t.number("xtol", 0.0, 1.0, false, "in [0, 1): a fraction of each parameter's range").value_or(0.01);
  const auto stop = t.number("stop_objective", 0.0, 1e300, false, "must be >= 0");
  o["stop_objective"] = stop ? json(*stop) : json(nullptr);
  o["seed"] = t.integer("seed", 0, std::numeric_limits<int>::max()).value_or(1);
  return o;
}

json parseSensitivity(const toml::table& root) {
  Table t(subTable(root, "sensitivity"), "sensitivity", {"enabled", "step"});
  json s;
  s["enabled"] = t.boolean("enabled").value_or(true);
  s["step"] = t.number("step", 0.0, 0.5, true, "in (0, 0.5]: a fraction of each parameter's range").value_or(0.05);
  return s;
}

struct Execution {
  int jobs = 0;
  int threads = 0;
  std::string scheduler;
};

Execution parseExecution(const toml::table& root) {
  Table t(subTable(root, "execution"), "execution", {"jobs", "threads", "scheduler"});
  Execution e;
  e.jobs = static_cast<int>(t.integer("jobs", 1, 4096).value_or(0));
  e.threads = static_cast<int>(t.integer("threads", 1, 4096).value_or(0));
  // Given, it must be an address: an empty string is refused, not taken for "not given".
  if (const auto scheduler = t.string("scheduler")) {
    checkSchedulerAddress(*scheduler, t.path("scheduler"));
    e.scheduler = *scheduler;
  }
  return e;
}

}  // namespace

int runCalibrate(const CalibrateOptions& opt) {
  // The config first: a bad config is reported as such, before the target.
  const toml::table base = io::loadConfigTable(opt.config);
  const std::string baseDir = io::configBaseDir(opt.config);
  const lab::RunConfig config = io::parseConfig(base, baseDir);
  if (config.test.type != lab::TestType::Triaxial)
    throw InputError(fmt::format("calibrate {}: test.type = \"{}\": calibration fits a triaxial test (test.type = \"triaxial\")",
                                 cutMiddle(opt.config), lab::name(config.test.type)));

  const fs::path targetPath = opt.target;
  std::error_code ec;
  if (!fs::is_regular_file(targetPath, ec))
    throw InputError(fmt::format("--target {}: not found or not a regular file", cutMiddle(opt.target)));
  toml::table root;
  try {
    root = toml::parse_file(opt.target);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("target error: {} line {}: {}", cutMiddle(opt.target), e.source().begin.line, e.description()));
  }
  static const std::vector<std::string> sections{"parameter", "target", "curve", "evaluation", "optimizer",
                                                 "sensitivity", "execution"};
  for (const auto& [k, v] : root)
    if (std::find(sections.begin(), sections.end(), std::string(k.str())) == sections.end())
      bad(std::string(k.str()), show(v), "unknown section; allowed: [[parameter]], [[target]], [curve] or [[curve]], [evaluation], "
                                         "[optimizer], [sensitivity], [execution]");

  json target;
  target["parameters"] = parseParameters(root, base, baseDir);
  const double configPressure = config.test.confiningPressure;
  target["targets"] = parseTargets(root, base, baseDir, configPressure);
  target["curves"] = parseCurves(root, fs::absolute(targetPath).parent_path(), config.test.finalAxialStrain, base, baseDir,
                                 configPressure);
  if (target["targets"].empty() && target["curves"].empty())
    bad("target", "(none)", "give at least one [[target]] (a summary.json value) or a [curve]");
  target["conditions"] = assignConditions(target, configPressure);
  target["seeds"] = parseSeeds(root, static_cast<long>(config.sample.seed));
  target["optimizer"] = parseOptimizer(root);
  target["sensitivity"] = parseSensitivity(root);
  Execution exec = parseExecution(root);
  if (opt.jobs > 0) exec.jobs = opt.jobs;
  if (!opt.scheduler.empty()) {
    checkSchedulerAddress(opt.scheduler, "--scheduler");
    exec.scheduler = opt.scheduler;
  }
  // Local runs share the cores: --jobs runs at once with cores/jobs threads each (OpenMP on more
  // threads than cores runs many times slower; results do not depend on the thread count).
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  if (exec.jobs <= 0) exec.jobs = cores;
  if (exec.threads <= 0 && exec.scheduler.empty()) exec.threads = std::max(1, cores / exec.jobs);

  const std::string source = opt.config.rfind("preset:", 0) == 0 ? opt.config : fs::absolute(opt.config).string();
  json inputs{{"format", "grainlab-calibration-1"},
              {"config", source},
              {"config_resolved", io::toTomlString(io::resolvedTable(config))},
              {"target_file", fs::absolute(targetPath).string()},
              {"target", target}};
  const fs::path out = opt.outDir.empty() ? fs::path("runs/calibration") : fs::path(opt.outDir);
  // A new or empty folder, or this calibration's own (its calibration.json); locked for the whole
  // calibration, the Python driver included (cli/study_folder.hpp).
  claimStudyFolder(out, "calibrate --out", "calibration.json", "calibration", true);
  const fs::path inputsFile = out / "calibration.json";
  if (fs::exists(inputsFile)) {
    json previous;
    try {
      std::ifstream in(inputsFile);
      in >> previous;
    } catch (const json::exception&) {
      throw InputError(fmt::format("--out {}: calibration.json there is not readable JSON; use another folder", cutMiddle(out.string())));
    }
    // A folder resumes only the calibration it holds: same config (resolved) and same target.
    for (const char* key : {"format", "config_resolved", "target"})
      if (previous.value(key, json()) != inputs[key])
        throw InputError(fmt::format("--out {}: holds a calibration with another {} ({}); resume with the same "
                                     "config and target, or choose another --out",
                                     cutMiddle(out.string()), std::string(key) == "target" ? "target" : "config",
                                     std::string(key) == "target" ? previous.value("target_file", "?") : previous.value("config", "?")));
  } else {
    io::writeFileAtomic(inputsFile, inputs.dump(1) + "\n");
  }

  const fs::path script = io::toolScript("calibrate.py");
  if (script.empty()) throw std::runtime_error("calibrate: tools/calibrate.py is not installed beside the program");
  std::vector<std::string> args{GRAINLAB_PYTHON, script.string(), "--folder", out.string(),
                                "--grainlab", io::executablePath().string(),
                                "--jobs", std::to_string(exec.jobs)};
  if (exec.threads > 0) args.insert(args.end(), {"--threads", std::to_string(exec.threads)});
  if (!exec.scheduler.empty()) args.insert(args.end(), {"--scheduler", exec.scheduler});
  if (opt.quiet) args.push_back("--quiet");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::fflush(nullptr);
  ::execv(GRAINLAB_PYTHON, argv.data());
  throw std::runtime_error(fmt::format("calibrate: cannot start {}: {}", GRAINLAB_PYTHON, std::strerror(errno)));
}

}  // namespace grainlab::cli

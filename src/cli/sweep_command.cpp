// `grainlab sweep`: a grid of config overrides run as parallel processes, then one comparison table
// and overlay plots. A failed case is reported and does not stop the others.
//
// The sweep's folder (README "Sweeps"): new or empty, or this sweep's own earlier folder, marked by
// its sweep.json (cli/study_folder.hpp). A re-run of the same sweep into it resumes: a case whose
// folder holds a completed run of the same resolved config is kept, every other case runs (again).
// A sweep with other --vary lists is refused there. The table is written whatever happens after
// the cases started (a lost scheduler, failed cases, SIGTERM), with one line on stderr saying what
// did not finish.
#include <fmt/format.h>
#include <sys/types.h>

#include <cctype>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <map>
#include <thread>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/study_folder.hpp"
#include "cli/sweep_dask.hpp"
#include "core/errors.hpp"
#include "io/checkpoint_file.hpp"
#include "io/config.hpp"
#include "io/input_file.hpp"
#include "io/install_paths.hpp"
#include "io/process.hpp"
#include "io/results.hpp"
#include "lab/replicates.hpp"

namespace grainlab::cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The most cases one sweep may have (the product of its --vary lists), checked before the grid is
// built: every case is validated first and gets a folder and a row.
constexpr double kMaxSweepCases = 10000;
// The most cases run at once (--jobs): each is a process.
constexpr int kMaxJobs = 1024;
// The most replicate seeds per case (--seeds).
constexpr int kMaxSeeds = 1000;
constexpr const char* kMarker = "sweep.json";
constexpr const char* kMarkerFormat = "grainlab-sweep-1";

struct Vary {
  std::string spec;  // as given, for messages
  std::string key;
  std::vector<std::string> parts;  // the key split at its dots, as applyOverride splits it
  std::vector<std::string> values;
};

std::string cut(const std::string& s) { return io::printable(s, 80); }

std::vector<std::string> keyParts(const std::string& key) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const auto dot = key.find('.', start);
    parts.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) return parts;
    start = dot + 1;
  }
}

// a is b or a table that holds b.
bool covers(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  return a.size() <= b.size() && std::equal(a.begin(), a.end(), b.begin());
}

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// Splits "a,b,[c,d],{ e = 1, f = 2 }" at the commas outside brackets, braces and quotes.
std::vector<std::string> splitTopLevel(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  int depth = 0;
  char quote = 0;
  for (char c : s) {
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '[' || c == '{') {
      ++depth;
    } else if (c == ']' || c == '}') {
      --depth;
    } else if (c == ',' && depth == 0) {
      out.push_back(cur);
      cur.clear();
      continue;
    }
    cur += c;
  }
  out.push_back(cur);
  return out;
}

Vary parseVary(const std::string& spec) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size())
    throw InputError(fmt::format("--vary {}: expected KEY=V1,V2,... e.g. contact.beta=0,0.15,1", cut(spec)));
  Vary v{spec, spec.substr(0, eq), keyParts(spec.substr(0, eq)), splitTopLevel(spec.substr(eq + 1))};
  std::map<std::string, std::size_t> seen;
  for (const auto& value : v.values) {
    if (trimmed(value).empty()) throw InputError(fmt::format("--vary {}: empty value in the list", cut(spec)));
    // The same value twice runs the same case twice under two labels: a mistake, refused.
    if (!seen.emplace(trimmed(value), seen.size()).second)
      throw InputError(fmt::format("--vary {}: the value {} is given twice; each value once", cut(spec),
                                   cut(trimmed(value))));
  }
  return v;
}

// A key varied twice (rows would be labelled with values that never ran), a key inside a varied
// table, or a --set of a varied key (the varied values would replace it): refused, naming both.
void checkKeys(const std::vector<Vary>& varies, const std::vector<std::string>& overrides) {
  for (std::size_t i = 0; i < varies.size(); ++i)
    for (std::size_t j = i + 1; j < varies.size(); ++j) {
      const Vary& a = varies[i];
      const Vary& b = varies[j];
      if (a.parts == b.parts)
        throw InputError(fmt::format("--vary {}: the key is varied twice (--vary {} and --vary {}); give all its "
                                     "values in one --vary",
                                     cut(a.key), cut(a.spec), cut(b.spec)));
      if (covers(a.parts, b.parts) || covers(b.parts, a.parts)) {
        const Vary& inner = a.parts.size() > b.parts.size() ? a : b;
        const Vary& outer = a.parts.size() > b.parts.size() ? b : a;
        throw InputError(fmt::format("--vary {}: the key is inside {}, which is varied too (--vary {}); vary one "
                                     "or the other",
                                     cut(inner.key), cut(outer.key), cut(outer.spec)));
      }
    }
  for (const auto& s : overrides) {
    const auto eq = s.find('=');
    if (eq == std::string::npos || eq == 0) continue;  // applyOverride names it
    const auto parts = keyParts(s.substr(0, eq));
    for (const auto& v : varies)
      if (covers(v.parts, parts))
        throw InputError(fmt::format("--set {}: {} is also varied (--vary {}), whose values would replace it; give "
                                     "the key once",
                                     cut(s), parts == v.parts ? "the key" : "its table " + cut(v.key), cut(v.spec)));
  }
}

// The product of the list sizes, refused above the limit before anything is built.
void checkGridSize(const std::vector<Vary>& varies) {
  double total = 1;
  std::string sizes;
  for (const auto& v : varies) {
    total *= static_cast<double>(v.values.size());
    sizes += (sizes.empty() ? "" : " x ") + std::to_string(v.values.size());
  }
  if (total > kMaxSweepCases)
    throw InputError(fmt::format("sweep: the grid has {:.6g} cases ({} values of {} --vary lists); the limit is {:.0f} "
                                 "cases per sweep",
                                 total, sizes, varies.size(), kMaxSweepCases));
}

// A folder name for one case: key=value pairs with anything unsafe replaced.
std::string caseName(std::size_t index, const std::vector<std::pair<std::string, std::string>>& sets) {
  std::string name = fmt::format("case{:03d}", index);
  for (const auto& [k, v] : sets) {
    std::string part = k.substr(k.rfind('.') + 1) + "=" + v;
    for (char& c : part)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-' && c != '=') c = '_';
    name += "_" + part.substr(0, 40);
  }
  return name;
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// The grid as the marker records it: the --vary lists in order (keys and values as given).
json gridJson(const std::vector<Vary>& varies) {
  json grid = json::array();
  for (const auto& v : varies) grid.push_back({{"key", v.key}, {"values", v.values}});
  return grid;
}

std::string gridText(const json& grid) {
  std::string s;
  if (!grid.is_array()) return "?";
  for (const auto& v : grid) {
    if (!v.is_object() || !v.contains("key") || !v.contains("values")) return "?";
    std::string values;
    for (const auto& x : v["values"]) values += (values.empty() ? "" : ",") + (x.is_string() ? x.get<std::string>() : "?");
    s += (s.empty() ? "--vary " : " --vary ") + (v["key"].is_string() ? v["key"].get<std::string>() : "?") + "=" + values;
  }
  return s;
}

// The sweep.json of an earlier sweep in the folder must be of the same grid.
void checkEarlierSweep(const fs::path& out, const json& grid) {
  const std::string text = io::readInputFile(out / kMarker, "sweep --out: sweep.json", io::kMaxConfigBytes);
  const json previous = json::parse(text, nullptr, false);
  if (!previous.is_object() || previous.value("format", "") != kMarkerFormat)
    throw InputError(fmt::format("sweep --out {}: its sweep.json is not a grainlab sweep's (format {}); give another "
                                 "folder",
                                 io::quotedPath(out), kMarkerFormat));
  if (previous.value("grid", json()) != grid)
    throw InputError(fmt::format("sweep --out {}: holds a sweep of another grid ({}); rerun that sweep to resume it, "
                                 "or give another folder for this one",
                                 io::quotedPath(out), cut(gridText(previous.value("grid", json())))));
}

// What identifies a case's run: its resolved config without output.dir (as `resume` compares a
// checkpoint's) and without solver.threads (results do not depend on it; --threads may differ
// between two sessions of a sweep).
std::uint64_t caseFingerprint(lab::RunConfig config) {
  config.solver.threads = 1;
  return io::configHash(config);
}

// A case finished by an earlier session: its folder holds a completed run of the same resolved config.
bool finishedEarlier(const fs::path& dir, std::uint64_t fingerprint) {
  std::error_code ec;
  if (!fs::is_regular_file(dir / "summary.json", ec) || !fs::is_regular_file(dir / "config.resolved.toml", ec))
    return false;
  try {
    const json summary =
        json::parse(io::readInputFile(dir / "summary.json", "summary.json", io::kMaxConfigBytes), nullptr, false);
    if (!summary.is_object() || summary.value("status", "") != "completed") return false;
    const std::string resolved = (dir / "config.resolved.toml").string();
    return caseFingerprint(io::parseConfig(io::loadConfigTable(resolved), io::configBaseDir(resolved))) == fingerprint;
  } catch (const InputError&) {
    return false;
  } catch (const io::FileError&) {
    return false;
  }
}

// sweep-stats.csv and sweep-stats.md (--seeds N): one row per case of the other --vary lists, over
// its N seeds (consecutive cases: the seed is the grid's innermost dimension). Every quantity as
// mean, sample standard deviation, min, max and n (the seeds that measured it: a null, or a seed
// that did not complete, is left out and counted, never taken as 0); critical_state_reached as the
// fraction of the seeds that reached it.
void writeSeedStatistics(const fs::path& out, const std::vector<Vary>& varies, std::size_t seedDim,
                         const std::vector<std::vector<std::pair<std::string, std::string>>>& cases,
                         const std::vector<json>& summaries, const std::vector<std::string>& columns) {
  const std::size_t seeds = varies[seedDim].values.size();
  std::string csv;
  for (std::size_t d = 0; d < varies.size(); ++d)
    if (d != seedDim) csv += csvField(varies[d].key) + ",";
  csv += "seeds,seeds_completed";
  for (const auto& c : columns)
    for (const char* part : {"_mean", "_std", "_min", "_max", "_n"}) csv += "," + c + part;
  csv += "\n";
  // The Markdown table: the quantities a results page quotes, as mean +- std (n >= 3) or the range.
  static const std::vector<std::pair<std::string, int>> shown{
      {"e0", 3},           {"phi_peak_deg", 1},      {"phi_res_deg", 1},   {"psi_max_deg", 1},
      {"psi_max_tan_deg", 1}, {"E50_MPa", 0},        {"end_q_over_p", 3},  {"end_void_ratio", 3},
      {"critical_state_reached", -1}};
  std::string md = "| ";
  for (std::size_t d = 0; d < varies.size(); ++d)
    if (d != seedDim) md += varies[d].key + " | ";
  md += "seeds |";
  for (const auto& [c, digits] : shown) md += " " + c + " |";
  md += "\n|";
  for (std::size_t d = 0; d < varies.size() + shown.size(); ++d) md += "---|";
  md += "\n";
  for (std::size_t first = 0; first < cases.size(); first += seeds) {
    std::size_t done = 0;
    for (std::size_t k = 0; k < seeds; ++k)
      if (summaries[first + k].is_object()) ++done;
    for (std::size_t d = 0; d < varies.size(); ++d)
      if (d != seedDim) {
        csv += csvField(cases[first][d].second) + ",";
        md += "| " + cases[first][d].second + " ";
      }
    csv += fmt::format("{},{}", seeds, done);
    md += fmt::format("| {} of {} |", done, seeds);
    std::map<std::string, lab::ReplicateStats> stats;
    for (const auto& c : columns) {
      std::vector<std::optional<double>> values;
      for (std::size_t k = 0; k < seeds; ++k) {
        const json& s = summaries[first + k];
        std::optional<double> v;
        if (s.is_object() && s.contains(c) && s[c].is_number()) v = s[c].get<double>();
        if (s.is_object() && s.contains(c) && s[c].is_boolean()) v = s[c].get<bool>() ? 1.0 : 0.0;
        values.push_back(v);
      }
      const lab::ReplicateStats st = lab::replicateStats(values);
      stats[c] = st;
      for (double x : {st.mean, st.std, st.min, st.max})
        csv += std::isfinite(x) ? fmt::format(",{:.8g}", x) : std::string(",");
      csv += fmt::format(",{}", st.n);
    }
    for (const auto& [c, digits] : shown) {
      const lab::ReplicateStats& st = stats[c];
      if (digits < 0)
        md += st.n == 0 ? " null |" : fmt::format(" {:.0f} of {} |", st.mean * static_cast<double>(st.n), st.n);
      else
        md += " " + lab::formatReplicates(st, digits) + " |";
    }
    csv += "\n";
    md += "\n";
  }
  io::writeFileAtomic(out / "sweep-stats.csv", csv);
  io::writeFileAtomic(out / "sweep-stats.md",
                      fmt::format("Over {} seeds per case (sample.seed {} to {}): mean ± sample standard deviation "
                                  "for 3 or more seeds, the range [min, max] for 2; (n of N) where only n seeds "
                                  "measured the value.\n\n",
                                  seeds, varies[seedDim].values.front(), varies[seedDim].values.back()) +
                          md);
}

const char* signalName(int sig) { return sig == SIGINT ? "SIGINT" : sig == SIGHUP ? "SIGHUP" : "SIGTERM"; }

}  // namespace

int runSweep(const SweepOptions& opt) {
  if (opt.seeds < 1 || opt.seeds > kMaxSeeds)
    throw InputError(fmt::format("--seeds = {}: must be in [1, {}]", opt.seeds, kMaxSeeds));
  if (opt.vary.empty() && opt.seeds < 2)
    throw InputError("sweep: give at least one --vary KEY=V1,V2,... or --seeds N (N >= 2 replicate seeds)");
  if (opt.jobs < 1 || opt.jobs > kMaxJobs)
    throw InputError(fmt::format("--jobs = {}: must be in [1, {}]", opt.jobs, kMaxJobs));
  if (!opt.scheduler.empty()) checkSchedulerAddress(opt.scheduler, "--scheduler");
  std::vector<Vary> varies;
  for (const auto& spec : opt.vary) varies.push_back(parseVary(spec));
  checkKeys(varies, opt.overrides);
  const toml::table base = io::loadConfigTable(opt.config);
  // --seeds N: the innermost dimension of the grid, sample.seed = s0, s0 + 1, ..., s0 + N - 1 with
  // s0 the config's seed (after --set), so the first replicate is the case a sweep without --seeds
  // runs. Refused where a seed cannot change the sample, or where the seed is varied already.
  std::size_t seedDim = 0;  // index of the seed dimension in varies, when seeds > 1
  if (opt.seeds > 1) {
    for (const auto& v : varies)
      if (covers(v.parts, {"sample", "seed"}))
        throw InputError(fmt::format("--seeds {}: sample.seed is varied too (--vary {}); give the seeds one way",
                                     opt.seeds, cut(v.spec)));
    toml::table table = base;
    for (const auto& s : opt.overrides) io::applyOverride(table, s);
    const lab::RunConfig config = io::parseConfig(table, io::configBaseDir(opt.config), false);
    if (!config.sample.packing.empty())
      throw InputError(fmt::format("--seeds {}: the sample is read from sample.packing = {}, so a seed cannot change "
                                   "it; replicate packings are separate runs",
                                   opt.seeds, io::quotedPath(config.sample.packing)));
    if (config.sample.seed > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()) -
                                 static_cast<std::uint64_t>(opt.seeds))
      throw InputError(fmt::format("--seeds {}: sample.seed = {} leaves no room for {} seeds after it", opt.seeds,
                                   config.sample.seed, opt.seeds));
    Vary seeds{fmt::format("--seeds {}", opt.seeds), "sample.seed", {"sample", "seed"}, {}};
    for (int k = 0; k < opt.seeds; ++k) seeds.values.push_back(std::to_string(config.sample.seed + k));
    seedDim = varies.size();
    varies.push_back(std::move(seeds));
  }
  checkGridSize(varies);

  // The grid: every combination, the last --vary changing fastest.
  using Sets = std::vector<std::pair<std::string, std::string>>;
  std::vector<Sets> cases{{}};
  for (const auto& v : varies) {
    std::vector<Sets> next;
    for (const auto& c : cases)
      for (const auto& value : v.values) {
        auto extended = c;
        extended.emplace_back(v.key, value);
        next.push_back(std::move(extended));
      }
    cases = std::move(next);
  }
  // Every case is validated before any starts: bad input is exit 2 with the usual message. Two
  // cases that resolve to the same config would be one run under two labels (values the config
  // reads the same, e.g. 1 and 1.0): refused.
  std::vector<std::uint64_t> hashes(cases.size());
  std::map<std::uint64_t, std::size_t> byHash;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    toml::table table = base;
    for (const auto& s : opt.overrides) io::applyOverride(table, s);
    for (const auto& [k, v] : cases[i]) io::applyOverride(table, k + "=" + v);
    const lab::RunConfig config = io::parseConfig(table, io::configBaseDir(opt.config));
    loadInputFiles(config);
    hashes[i] = caseFingerprint(config);
    const auto [it, inserted] = byHash.emplace(hashes[i], i);
    if (!inserted) {
      const Sets& other = cases[it->second];
      std::size_t k = 0;
      while (k + 1 < varies.size() && other[k].second == cases[i][k].second) ++k;
      throw InputError(fmt::format("--vary {}: the values {} and {} give the same config (cases {} and {}); each "
                                   "value must make a difference",
                                   cut(varies[k].key), cut(other[k].second), cut(cases[i][k].second), it->second, i));
    }
  }
  const fs::path out = opt.outDir.empty() ? fs::path("runs/sweep") : fs::path(opt.outDir);
  const json grid = gridJson(varies);
  const StudyFolder folder = claimStudyFolder(out, "sweep --out", kMarker, "sweep", false);
  if (!folder.fresh) checkEarlierSweep(out, grid);
  std::vector<std::string> names(cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) names[i] = caseName(i, cases[i]);
  {
    const std::string source = opt.config.rfind("preset:", 0) == 0 ? opt.config : fs::absolute(opt.config).string();
    io::writeFileAtomic(out / kMarker, json{{"format", kMarkerFormat},
                                            {"config", source},
                                            {"set", opt.overrides},
                                            {"grid", grid},
                                            {"seeds", opt.seeds},
                                            {"cases", names}}
                                               .dump(1) +
                                           "\n");
  }
  const std::string self = io::executablePath().string();

  // A case's outcome: kept (finished by an earlier session), completed, failed (exit code),
  // stopped (by the signal that stopped the sweep) or not run.
  enum class State { NotRun, Kept, Completed, Failed, Stopped };
  struct Job {
    State state = State::NotRun;
    int code = -1;
  };
  std::vector<Job> jobs(cases.size());
  std::size_t kept = 0;
  for (std::size_t i = 0; i < cases.size(); ++i)
    if (finishedEarlier(out / names[i], hashes[i])) {
      jobs[i].state = State::Kept;
      ++kept;
    }
  if (kept > 0 && !opt.quiet)
    std::fprintf(stderr, "sweep: %zu of %zu cases completed earlier in %s are kept; running %zu\n", kept, cases.size(),
                 io::printable(out.native(), 240).c_str(), cases.size() - kept);

  // Several cases at once share the cores: without --threads each gets cores / jobs threads.
  // OpenMP on more threads than cores is not just slower but pathological (each step's barriers
  // wait for descheduled threads: 10-40x slower measured on 2 cores); results do not depend on
  // the thread count, so this changes only the speed.
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  int threadsPerCase = opt.threads;
  if (threadsPerCase <= 0 && opt.jobs > 1) threadsPerCase = std::max(1, cores / opt.jobs);
  if (threadsPerCase > 0 && threadsPerCase * opt.jobs > cores)
    std::fprintf(stderr,
                 "grainlab: warning: --jobs %d x --threads %d = %d threads on %d cores; oversubscribed OpenMP "
                 "runs many times slower\n",
                 opt.jobs, threadsPerCase, opt.jobs * threadsPerCase, cores);

  // From here SIGTERM, SIGINT and SIGHUP stop the cases (passed on to them) and end the sweep with
  // its table; the cases also die with the sweep when it is killed (startProcess dieWithParent).
  io::StopForwarding stop;
  std::string lostReason;  // why cases were not run (a lost scheduler), for the last line
  // With --scheduler the cases run on a Dask cluster instead (sweep_dask.hpp); the table is the same
  // with two more columns: how many attempts each case took (> 1: its worker was lost) and where.
  std::vector<DaskCaseResult> dask;
  if (!opt.scheduler.empty()) {
    std::vector<DaskCase> daskCases;
    std::vector<std::size_t> index;
    for (std::size_t i = 0; i < cases.size(); ++i) {
      if (jobs[i].state == State::Kept) continue;
      DaskCase c{names[i], opt.overrides};
      for (const auto& [k, v] : cases[i]) c.sets.push_back(k + "=" + v);
      daskCases.push_back(std::move(c));
      index.push_back(i);
    }
    dask.resize(cases.size());
    if (!daskCases.empty()) {
      DaskOutcome outcome = runCasesOnDask(opt, self, out, daskCases, opt.threads);
      lostReason = outcome.error;
      for (std::size_t n = 0; n < index.size(); ++n) {
        const DaskCaseResult& r = outcome.cases[n];
        dask[index[n]] = r;
        if (!r.ran) continue;
        jobs[index[n]].code = r.exitCode;
        jobs[index[n]].state = r.exitCode == 0 ? State::Completed : State::Failed;
      }
    }
  } else {
    std::map<pid_t, std::size_t> running;
    std::map<pid_t, std::size_t> slots;  // the CPU block of each running job
    const bool bindJobs = io::ompBindingRequested();
    const std::vector<int> cpus = io::allowedCpus();
    std::size_t next = 0, done = kept;
    while (true) {
      while (!stop.stopSignal() && next < cases.size() && running.size() < static_cast<std::size_t>(opt.jobs)) {
        const std::size_t i = next++;
        if (jobs[i].state == State::Kept) continue;
        std::vector<std::string> args{self, "run", opt.config, "--out", (out / names[i]).string(), "--quiet"};
        if (threadsPerCase > 0) args.insert(args.end(), {"--threads", std::to_string(threadsPerCase)});
        for (const auto& s : opt.overrides) args.insert(args.end(), {"--set", s});
        for (const auto& [k, v] : cases[i]) args.insert(args.end(), {"--set", k + "=" + v});
        // With OMP_PROC_BIND exported, each concurrent job gets its own CPUs (OMP_PLACES), or
        // libgomp would bind every job's first thread to the same core.
        std::size_t slot = 0;
        while (std::any_of(running.begin(), running.end(), [&](const auto& r) { return slots[r.first] == slot; })) ++slot;
        std::vector<std::string> env;
        std::vector<int> jobCpus;
        if (bindJobs) {
          env.push_back("OMP_PLACES=" + io::ompPlacesFor(slot, std::max(threadsPerCase, 1), cpus));
          jobCpus = io::cpusFor(slot, std::max(threadsPerCase, 1), cpus);
        }
        pid_t pid;
        try {
          pid = io::startProcess(args, io::ChildOutput::toFile(out / (names[i] + ".log")), true, env, jobCpus);
        } catch (const io::FileError& e) {
          // Not started (e.g. its log cannot be written): the case failed; the others go on.
          std::fprintf(stderr, "grainlab: sweep: %s: %s\n", names[i].c_str(), io::printable(e.what(), 300).c_str());
          jobs[i] = {State::Failed, 127};
          ++done;
          continue;
        }
        io::StopForwarding::track(pid);
        running[pid] = i;
        slots[pid] = slot;
      }
      if (running.empty()) break;
      const auto [pid, code] = io::waitAnyProcess();
      const auto it = running.find(pid);
      if (it == running.end()) continue;
      io::StopForwarding::untrack(pid);
      const std::size_t i = it->second;
      slots.erase(it->first);
      running.erase(it);
      jobs[i].code = code;
      jobs[i].state = code == 0 ? State::Completed : stop.stopSignal() ? State::Stopped : State::Failed;
      ++done;
      if (!opt.quiet)
        std::fprintf(stderr, "[%zu/%zu] %s: %s\n", done, cases.size(), names[i].c_str(),
                     code == 0 ? "completed" : fmt::format("failed (exit {})", code).c_str());
    }
  }
  const int stopped = stop.stopSignal();

  // The comparison table: one row per case, its overrides and its macro-parameters.
  static const std::vector<std::string> columns{
      "e0", "phi_peak_deg", "eps1_at_peak", "phi_res_deg", "psi_max_deg", "E_MPa", "E50_MPa", "nu",
      "cs_q_over_p", "cs_void_ratio", "inertial_number", "inertial_number_max", "lateral_stress_max_deviation",
      "steps", "wall_seconds", "psi_max_tan_deg", "critical_state_reached", "end_q_over_p", "end_void_ratio"};
  std::string csv = "case,status";
  for (const auto& v : varies) csv += "," + csvField(v.key);
  for (const auto& c : columns) csv += "," + c;
  if (!dask.empty()) csv += ",attempts,workers";
  csv += "\n";
  std::size_t completed = 0, failed = 0, notRun = 0, interrupted = 0;
  std::string firstFailed;
  std::vector<json> summaries(cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Job& job = jobs[i];
    const bool ok = job.state == State::Kept || job.state == State::Completed;
    json& summary = summaries[i];
    if (ok) {
      try {
        summary = nlohmann::json::parse(
            io::readInputFile(out / names[i] / "summary.json", "summary.json", io::kMaxConfigBytes), nullptr, false);
      } catch (const InputError&) {
        // Missing or unreadable: the row keeps empty cells.
      }
    }
    std::string status;
    switch (job.state) {
      case State::Kept:
      case State::Completed:
        status = "completed";
        ++completed;
        break;
      case State::Failed:
        status = fmt::format("failed (exit {})", job.code);
        if (firstFailed.empty()) firstFailed = fmt::format("{}: exit {}", names[i], job.code);
        ++failed;
        break;
      case State::Stopped:
        status = fmt::format("stopped ({})", signalName(stopped));
        ++interrupted;
        break;
      case State::NotRun:
        status = "not run";
        ++notRun;
        break;
    }
    csv += csvField(names[i]) + "," + csvField(status);
    for (const auto& [k, v] : cases[i]) csv += "," + csvField(v);
    for (const auto& c : columns) {
      csv += ",";
      if (ok && summary.contains(c) && summary[c].is_number()) csv += fmt::format("{:.8g}", summary[c].get<double>());
      if (ok && summary.contains(c) && summary[c].is_boolean()) csv += summary[c].get<bool>() ? "true" : "false";
    }
    // attempts 0: the case was completed by an earlier session of the sweep, or not run.
    if (!dask.empty()) csv += fmt::format(",{},{}", dask[i].attempts, csvField(dask[i].workers));
    csv += "\n";
  }
  io::writeFileAtomic(out / "sweep.csv", csv);
  if (opt.seeds > 1) writeSeedStatistics(out, varies, seedDim, cases, summaries, columns);
  // Overlay plots: tools/plot_sweep.py with an argument vector (no shell), output discarded.
  const fs::path script = io::toolScript("plot_sweep.py");
  if (stopped) {
    // No plots: the sweep was asked to stop.
  } else if (script.empty()) {
    std::fprintf(stderr, "grainlab: warning: plot_sweep.py not found in share/grainlab/tools beside the executable\n");
  } else {
    try {
      const pid_t pid =
          io::startProcess({GRAINLAB_PYTHON, script.string(), out.string()}, io::ChildOutput::discard(), true);
      io::StopForwarding::track(pid);
      const int rc = io::waitProcess(pid);
      io::StopForwarding::untrack(pid);
      if (rc != 0 && !stop.stopSignal()) std::fprintf(stderr, "grainlab: warning: sweep plots failed\n");
    } catch (const io::FileError& e) {
      std::fprintf(stderr, "grainlab: warning: sweep plots: %s\n", e.what());
    }
  }
  const std::string table = io::printable((out / "sweep.csv").native(), 240);
  if (!opt.quiet)
    std::printf("%zu cases, %zu failed; table in %s\n", cases.size(), cases.size() - completed, table.c_str());
  // What did not finish, in one line (also with --quiet: it is the sweep's outcome).
  if (completed < cases.size()) {
    std::string what = fmt::format("{} of {} cases completed", completed, cases.size());
    if (failed) what += fmt::format(", {} failed (first {})", failed, firstFailed);
    if (interrupted) what += fmt::format(", {} stopped", interrupted);
    if (notRun) what += fmt::format(", {} not run", notRun);
    const std::string why = stopped ? fmt::format("interrupted by {}", signalName(stopped)) : lostReason;
    std::fprintf(stderr, "grainlab: sweep: %s; table of what finished in %s; the same command runs the rest\n",
                 io::printable((why.empty() ? "" : why + ": ") + what, 400).c_str(), table.c_str());
  }
  if (stopped) return 128 + stopped;
  return completed == cases.size() ? 0 : 1;
}

}  // namespace grainlab::cli

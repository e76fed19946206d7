// `grainlab sweep`: a grid of config overrides run as parallel processes, then one comparison table
// and overlay plots. A failed case is reported and does not stop the others.
#include <fmt/format.h>

#include <cctype>
#include <filesystem>
#include <map>
#include <thread>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "cli/sweep_dask.hpp"
#include "core/errors.hpp"
#include "io/config.hpp"
#include "io/input_file.hpp"
#include "io/install_paths.hpp"
#include "io/process.hpp"
#include "io/results.hpp"

namespace grainlab::cli {

namespace fs = std::filesystem;

namespace {

struct Vary {
  std::string key;
  std::vector<std::string> values;
};

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
    throw InputError(fmt::format("--vary {}: expected KEY=V1,V2,... e.g. contact.beta=0,0.15,1", spec));
  Vary v{spec.substr(0, eq), splitTopLevel(spec.substr(eq + 1))};
  for (const auto& value : v.values)
    if (value.empty()) throw InputError(fmt::format("--vary {}: empty value in the list", spec));
  return v;
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

}  // namespace

int runSweep(const SweepOptions& opt) {
  if (opt.vary.empty()) throw InputError("sweep: give at least one --vary KEY=V1,V2,...");
  if (opt.jobs < 1) throw InputError(fmt::format("--jobs = {}: must be >= 1", opt.jobs));
  if (!opt.scheduler.empty()) checkSchedulerAddress(opt.scheduler, "--scheduler");
  std::vector<Vary> varies;
  for (const auto& spec : opt.vary) varies.push_back(parseVary(spec));

  // The grid: every combination, the last --vary changing fastest.
  std::vector<std::vector<std::pair<std::string, std::string>>> cases{{}};
  for (const auto& v : varies) {
    std::vector<std::vector<std::pair<std::string, std::string>>> next;
    for (const auto& c : cases)
      for (const auto& value : v.values) {
        auto extended = c;
        extended.emplace_back(v.key, value);
        next.push_back(std::move(extended));
      }
    cases = std::move(next);
  }
  // Every case is validated before any starts: bad input is exit 2 with the usual message.
  for (const auto& c : cases) {
    toml::table table = io::loadConfigTable(opt.config);
    for (const auto& s : opt.overrides) io::applyOverride(table, s);
    for (const auto& [k, v] : c) io::applyOverride(table, k + "=" + v);
    loadInputFiles(io::parseConfig(table, io::configBaseDir(opt.config)));
  }
  const fs::path out = opt.outDir.empty() ? fs::path("runs/sweep") : fs::path(opt.outDir);
  io::createDirectories(out);
  const std::string self = io::executablePath().string();

  struct Job {
    std::string name;
    int status = -1;
  };
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
  std::vector<Job> jobs(cases.size());
  std::map<pid_t, std::size_t> running;
  std::size_t next = 0, done = 0;
  auto wait_one = [&] {
    const auto [pid, code] = io::waitAnyProcess();
    if (!running.count(pid)) return;
    const std::size_t i = running[pid];
    running.erase(pid);
    jobs[i].status = code;
    ++done;
    if (!opt.quiet)
      std::fprintf(stderr, "[%zu/%zu] %s: %s\n", done, cases.size(), jobs[i].name.c_str(),
                   jobs[i].status == 0 ? "completed" : fmt::format("failed (exit {})", jobs[i].status).c_str());
  };
  // With --scheduler the cases run on a Dask cluster instead (sweep_dask.hpp); the table is the same
  // with two more columns: how many attempts each case took (> 1: its worker was lost) and where.
  std::vector<DaskCaseResult> dask;
  if (!opt.scheduler.empty()) {
    std::vector<DaskCase> daskCases;
    for (std::size_t i = 0; i < cases.size(); ++i) {
      jobs[i].name = caseName(i, cases[i]);
      DaskCase c{jobs[i].name, opt.overrides};
      for (const auto& [k, v] : cases[i]) c.sets.push_back(k + "=" + v);
      daskCases.push_back(std::move(c));
    }
    dask = runCasesOnDask(opt, self, out, daskCases, opt.threads);
    for (std::size_t i = 0; i < cases.size(); ++i) jobs[i].status = dask[i].exitCode;
    done = cases.size();
  }
  while (done < cases.size()) {
    while (next < cases.size() && running.size() < static_cast<std::size_t>(opt.jobs)) {
      jobs[next].name = caseName(next, cases[next]);
      std::vector<std::string> args{self, "run", opt.config, "--out", (out / jobs[next].name).string(), "--quiet"};
      if (threadsPerCase > 0) args.insert(args.end(), {"--threads", std::to_string(threadsPerCase)});
      for (const auto& s : opt.overrides) args.insert(args.end(), {"--set", s});
      for (const auto& [k, v] : cases[next]) args.insert(args.end(), {"--set", k + "=" + v});
      const pid_t pid = io::startProcess(args, io::ChildOutput::toFile(out / (jobs[next].name + ".log")));
      running[pid] = next++;
    }
    wait_one();
  }

  // The comparison table: one row per case, its overrides and its macro-parameters.
  static const std::vector<std::string> columns{
      "e0", "phi_peak_deg", "eps1_at_peak", "phi_res_deg", "psi_max_deg", "E_MPa", "E50_MPa", "nu",
      "cs_q_over_p", "cs_void_ratio", "inertial_number", "inertial_number_max", "lateral_stress_max_deviation",
      "steps", "wall_seconds"};
  std::string csv = "case,status";
  for (const auto& v : varies) csv += "," + csvField(v.key);
  for (const auto& c : columns) csv += "," + c;
  if (!dask.empty()) csv += ",attempts,workers";
  csv += "\n";
  int failed = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    nlohmann::json summary;
    if (jobs[i].status == 0) {
      try {
        summary = nlohmann::json::parse(
            io::readInputFile(out / jobs[i].name / "summary.json", "summary.json", io::kMaxConfigBytes), nullptr, false);
      } catch (const InputError&) {
        // Missing or unreadable: the row keeps empty cells.
      }
    }
    const std::string status = jobs[i].status == 0 ? "completed" : fmt::format("failed (exit {})", jobs[i].status);
    failed += jobs[i].status != 0;
    csv += csvField(jobs[i].name) + "," + csvField(status);
    for (const auto& [k, v] : cases[i]) csv += "," + csvField(v);
    for (const auto& c : columns) {
      csv += ",";
      if (jobs[i].status == 0 && summary.contains(c) && summary[c].is_number())
        csv += fmt::format("{:.8g}", summary[c].get<double>());
    }
    if (!dask.empty()) csv += fmt::format(",{},{}", dask[i].attempts, csvField(dask[i].workers));
    csv += "\n";
  }
  io::writeFileAtomic(out / "sweep.csv", csv);
  // Overlay plots: tools/plot_sweep.py with an argument vector (no shell), output discarded.
  const fs::path script = io::toolScript("plot_sweep.py");
  if (script.empty()) {
    std::fprintf(stderr, "grainlab: warning: plot_sweep.py not found in share/grainlab/tools beside the executable\n");
  } else {
    try {
      if (io::runProcess({GRAINLAB_PYTHON, script.string(), out.string()}, io::ChildOutput::discard()) != 0)
        std::fprintf(stderr, "grainlab: warning: sweep plots failed\n");
    } catch (const io::FileError& e) {
      std::fprintf(stderr, "grainlab: warning: sweep plots: %s\n", e.what());
    }
  }
  if (!opt.quiet)
    std::printf("%zu cases, %d failed; table in %s\n", cases.size(), failed,
                io::printable((out / "sweep.csv").native(), 240).c_str());
  return failed == 0 ? 0 : 1;
}

}  // namespace grainlab::cli

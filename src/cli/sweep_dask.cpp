// `grainlab sweep --scheduler tcp://HOST:PORT`: the cases of the grid run on a Dask cluster.
// The cluster side is Python (Debian's python3-distributed): this file writes the cases to a
// manifest, starts tools/dask_runner.py with an argument vector and reads back each case's exit
// code and attempts; the table and plots are then made exactly as for a local sweep.
#include "cli/sweep_dask.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "io/install_paths.hpp"
#include "io/process.hpp"
#include "core/errors.hpp"
#include "io/results.hpp"


namespace grainlab::cli {

namespace fs = std::filesystem;
using nlohmann::json;

void checkSchedulerAddress(const std::string& address, const std::string& where) {
  const auto scheme = address.find("://");
  const auto colon = address.rfind(':');
  const std::string proto = scheme == std::string::npos ? "" : address.substr(0, scheme);
  const std::string port = colon == std::string::npos ? "" : address.substr(colon + 1);
  const bool portOk = !port.empty() && port.size() <= 5 && port.find_first_not_of("0123456789") == std::string::npos &&
                      std::stol(port) <= 65535;
  if ((proto != "tcp" && proto != "tls") || colon <= scheme + 3 || !portOk) {
    const std::string shown =
        address.empty() ? "\"\" (empty)" : address.size() > 80 ? address.substr(0, 77) + "..." : address;
    throw InputError(fmt::format("{} = {}: expected a Dask scheduler address tcp://HOST:PORT (or tls://HOST:PORT)",
                                 where, shown));
  }
}

DaskOutcome runCasesOnDask(const SweepOptions& opt, const std::string& executable, const fs::path& out,
                           const std::vector<DaskCase>& cases, int threads) {
  checkSchedulerAddress(opt.scheduler, "--scheduler");
  // Workers may run in other folders or on other machines: the config by absolute path (its text
  // travels too, for workers that do not see that path), the results folder absolute.
  const bool preset = opt.config.rfind("preset:", 0) == 0;
  json manifest{{"scheduler", opt.scheduler},
                {"executable", executable},
                {"config", preset ? opt.config : fs::absolute(opt.config).string()},
                {"out", fs::absolute(out).string()},
                {"shared_out", opt.sharedOut},
                {"threads", threads},
                {"quiet", opt.quiet}};
  json list = json::array();
  for (const auto& c : cases) list.push_back({{"name", c.name}, {"sets", c.sets}});
  manifest["cases"] = list;
  const fs::path manifestFile = out / "dask-manifest.json";
  const fs::path resultsFile = out / "dask-results.json";
  io::writeFileAtomic(manifestFile, manifest.dump(1) + "\n");
  fs::remove(resultsFile);

  const fs::path script = io::toolScript("dask_runner.py");
  if (script.empty()) throw std::runtime_error("sweep: tools/dask_runner.py is not installed beside the program");
  // The runner dies with the sweep; a stop signal is passed on to it, and it reports what finished.
  const pid_t pid = io::startProcess({GRAINLAB_PYTHON, script.string(), "sweep", manifestFile.string(),
                                      resultsFile.string()},
                                     io::ChildOutput::inherit(), true);
  io::StopForwarding::track(pid);
  const int rc = io::waitProcess(pid);
  io::StopForwarding::untrack(pid);
  // The runner rewrites its results file as each case finishes, so what it finished is known
  // however it ended.
  json results;
  std::ifstream in(resultsFile);
  if (in) {
    try {
      in >> results;
    } catch (const json::exception&) {
      results = nullptr;
    }
  }
  DaskOutcome outcome;
  outcome.cases.resize(cases.size());
  const json none = json::object();
  const json& done = results.is_object() && results.contains("cases") && results["cases"].is_object() ? results["cases"] : none;
  std::size_t missing = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const json r = done.value(cases[i].name, json());
    if (!r.is_object() || !r.contains("exit_code") || !r["exit_code"].is_number_integer()) {
      ++missing;
      continue;
    }
    DaskCaseResult& c = outcome.cases[i];
    c.ran = true;
    c.exitCode = r["exit_code"].get<int>();
    c.attempts = r.value("attempts", 1);
    if (r.contains("workers") && r["workers"].is_array())
      for (const auto& w : r["workers"])
        if (w.is_string()) c.workers += (c.workers.empty() ? "" : " then ") + w.get<std::string>();
  }
  if (results.is_object() && results.contains("error") && results["error"].is_string())
    outcome.error = results["error"].get<std::string>();
  else if (missing > 0)
    outcome.error = fmt::format("the Dask runner {} stopped ({}) before every case was reported", script.string(),
                                rc > 128 ? fmt::format("signal {}", rc - 128) : fmt::format("exit {}", rc));
  return outcome;
}

}  // namespace grainlab::cli

// `grainlab analyse DIR`: the micromechanics of a finished run recomputed from its saved
// snapshots (DIR/micro/, io/micro_snapshot.hpp), so that older runs can be analysed again with
// other options without rerunning. Writes DIR/micro/analysis.csv and analysis.json, the class
// averages of every snapshot (classes_NNNN.csv, classes_NNNN.vtu, classes.pvd) and the plots
// (DIR/plots/rose_*.png, micro_*.png) drawn by tools/plot_micro.py.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "io/install_paths.hpp"
#include "io/process.hpp"
#include "core/errors.hpp"
#include "io/micro_output.hpp"
#include "io/micro_snapshot.hpp"
#include "io/results.hpp"
#include "io/vtu_piece.hpp"


namespace grainlab::cli {

namespace fs = std::filesystem;

namespace {

// Runs `python tools/plot_micro.py DIR` from the data folder beside the executable (an argument
// vector, no shell); false when the script is missing or failed.
bool drawPlots(const fs::path& dir, bool quiet) {
  const fs::path script = io::toolScript("plot_micro.py");
  if (script.empty() || !fs::exists(script)) return false;
  return io::runProcess({GRAINLAB_PYTHON, script.string(), dir.string()},
                        quiet ? io::ChildOutput::discard() : io::ChildOutput::inherit()) == 0;
}

std::string show(const std::optional<double>& v, const char* format = "{:7.3f}") {
  return v ? fmt::format(fmt::runtime(format), *v) : std::string("   null");
}

}  // namespace

int runAnalyse(const AnalyseOptions& opt) {
  const fs::path dir(opt.dir);
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(fmt::format("analyse: DIR = \"{}\": not a folder (expected a grainlab results folder)", opt.dir));
  if (opt.classDivisions < 1 || opt.classDivisions > 16)
    throw InputError(fmt::format("analyse: --classes = {}: allowed 1 to 16 (24·N² orientation classes)",
                                 opt.classDivisions));
  const fs::path micro = dir / "micro";
  if (!fs::exists(micro / "snapshots.csv", ec))
    throw InputError(fmt::format("analyse: {}: does not exist (the run saved no micromechanics snapshots)",
                                 (micro / "snapshots.csv").string()));
  const std::vector<io::MicroSnapshotInfo> index = io::readMicroIndex(micro);
  if (index.empty())
    throw InputError(fmt::format("analyse: {}: lists no snapshot", (micro / "snapshots.csv").string()));

  lab::MicroOptions options;
  options.classDivisions = opt.classDivisions;
  options.fourthOrder = opt.fourthOrder;
  const lab::MicroAnalyzer analyzer(options);
  std::vector<io::AnalysedSnapshot> rows;
  lab::MicroColumnSet columns;
  columns.fourthOrder = opt.fourthOrder;
  for (const auto& info : index) {
    const lab::MicroNetwork network = io::readMicroSnapshot(micro, info);
    io::AnalysedSnapshot row{info, {}};
    try {
      row.analysis = analyzer.analyse(network);
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("analyse: snapshot {} of {}: {}", info.index, micro.string(), e.what()));
    }
    columns.nonSpherical = columns.nonSpherical || row.analysis.nonSpherical;
    rows.push_back(std::move(row));
  }

  std::vector<double> labels;
  nlohmann::json snapshots = nlohmann::json::array();
  for (const auto& row : rows) {
    const int k = row.info.index;
    io::writeFileAtomic(micro / fmt::format("classes_{:04d}.csv", k), io::orientationClassesCsv(analyzer.classes(), row.analysis));
    io::writeFileAtomic(micro / fmt::format("classes_{:04d}.vtu", k), io::orientationClassesVtu(analyzer.classes(), row.analysis));
    labels.push_back(row.info.eps1);
    snapshots.push_back(io::microAnalysisJson(row));
  }
  // classes.pvd lists classes_0000.vtu, ... by position, so it needs the indices 0..n−1.
  bool consecutive = true;
  for (std::size_t i = 0; i < rows.size(); ++i) consecutive = consecutive && rows[i].info.index == static_cast<int>(i);
  if (consecutive) io::writeFileAtomic(micro / "classes.pvd", io::pvdCollection("classes", labels));

  // The peak: the largest measured q/p (the contact stress's where none was measured).
  auto ratio = [](const lab::MicroAnalysis& m) { return m.qOverPMeasured ? m.qOverPMeasured : m.qOverPContacts; };
  std::size_t peak = rows.size() - 1;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto here = ratio(rows[i].analysis), best = ratio(rows[peak].analysis);
    if (here && (!best || *here > *best)) peak = i;
  }
  const nlohmann::json summary{
      {"format", "grainlab-micro-analysis-1"},
      {"class_divisions", opt.classDivisions},
      {"classes", analyzer.classes().size()},
      {"fourth_order", opt.fourthOrder},
      {"axial_axis", "z"},
      {"start", rows.front().info.index},
      {"peak", rows[peak].info.index},
      {"end", rows.back().info.index},
      {"peak_by", rows[peak].analysis.qOverPMeasured ? "q_over_p" : "q_over_p_contacts"},
      {"snapshots", snapshots}};
  io::writeFileAtomic(micro / "analysis.csv", io::microAnalysisCsv(rows, columns));
  io::writeFileAtomic(micro / "analysis.json", summary.dump(1) + "\n");

  if (!opt.quiet) {
    std::printf("snapshot    eps1      Z   Z_mech    a_r     a_n     a_t    q/p  q/p_sff  sff_err\n");
    for (const auto& [info, m] : rows) {
      auto mag = [](const std::optional<lab::Anisotropy>& a) {
        return a ? std::optional<double>(a->magnitude) : std::nullopt;
      };
      std::printf("%8d %7.4f %6.3f %s %s %s %s %s %s %s\n", info.index, info.eps1, m.coordination.Z,
                  show(m.coordination.Zmech).c_str(), show(mag(m.ar)).c_str(), show(mag(m.an)).c_str(),
                  show(mag(m.at)).c_str(), show(ratio(m)).c_str(), show(m.qOverPSff).c_str(),
                  show(m.sffError).c_str());
    }
    std::printf("wrote %s (analysis.csv, analysis.json, classes_NNNN.csv/.vtu)\n", micro.string().c_str());
  }
  if (opt.plots && !drawPlots(dir, opt.quiet))
    std::fprintf(stderr, "grainlab: warning: plotting failed (the analysis files are complete without plots)\n");
  return 0;
}

}  // namespace grainlab::cli

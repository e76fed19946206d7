#pragma once
// Results of the micromechanical analysis (docs/micromechanics.md §5): the class averages as CSV
// and as a VTK grid on the unit sphere, the table of every analysed snapshot, and its JSON form.
// A value that could not be measured is an empty CSV field, a JSON null, or NaN in VTK cell data
// (ParaView shows it in its NaN colour).
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

#include "io/micro_snapshot.hpp"
#include "lab/micromechanics.hpp"

namespace grainlab::io {

struct AnalysedSnapshot {
  MicroSnapshotInfo info;
  lab::MicroAnalysis analysis;
};

// classes_NNNN.csv: per class its centre n, area [sr], contact count (n and −n both counted),
// density = count/(2·Nc·area) [1/sr] beside the fitted E(n), mean normal force beside the fitted
// f̄ⁿ(n), mean tangential force, mean branch vector parts, and the four corners of the patch.
std::string orientationClassesCsv(const lab::OrientationClasses& classes, const lab::MicroAnalysis& m);
// classes_NNNN.vtu: one quad per class on the unit sphere with the same values as cell data.
std::string orientationClassesVtu(const lab::OrientationClasses& classes, const lab::MicroAnalysis& m);

// analysis.csv: one row per snapshot (index, step, eps1, counts, measured and rebuilt stress
// ratios, then the time-series columns of lab::microColumnNames).
std::string microAnalysisCsv(const std::vector<AnalysedSnapshot>& rows, const lab::MicroColumnSet& set);
// Everything measured on one snapshot, tensors in full (rows of 3).
nlohmann::json microAnalysisJson(const AnalysedSnapshot& s);

}  // namespace grainlab::io

#pragma once
// The run report: what a prepared sample and a finished test say in summary.json (docs/laboratory.md
// §3.4), built in the laboratory from its results, so that the command line only assembles a run,
// writes its files and prints.
//
// Each function adds its keys to a summary object (a JSON object; the keys are sorted when
// written, so their order here does not matter) and returns the warnings meant for the console. A
// warning that also belongs in the summary is pushed to its "warnings" list as well. A value that
// cannot be measured is null, never 0; a non-finite number is refused (SimulationError).
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lab/macro.hpp"
#include "lab/moduli.hpp"
#include "lab/protocols.hpp"
#include "lab/shear_band.hpp"

namespace grainlab::lab {

using Json = nlohmann::json;

// Warnings for the console, in the order they arose (the command line prefixes "grainlab: warning: ").
using ConsoleWarnings = std::vector<std::string>;

// The prepared sample: e0 and its target, the preparation method and search, the grading, the
// isotropic state, Z, the fabric, the deposition or under-compaction report, dt, the growth curve.
// `fromPacking`: the sample came from sample.packing (taken as it is).
ConsoleWarnings reportPreparation(const RunConfig& config, const PreparationResult& prep, const Laboratory& lab,
                                  bool fromPacking, Json& summary);

// The small-strain probe (lab/moduli.hpp): E0_MPa, nu0 (null where the probe did not measure an
// isotropic elastic response), E0_method, E0_probe; E_MPa and nu repeat E0_MPa and nu0.
void reportProbe(const ModulusProbe& probe, Json& summary);

// What a finished test reports: its macro-values (the monotonic curve's peak, residual, dilatancy,
// moduli, critical state; or the oedometer's, cyclic tests' and stress path's own), the undrained
// keys, the run's rates and checks, the micromechanics at the peak and the end.
struct ShearReport {
  ConsoleWarnings warnings;
  // Rowe's data of the monotonic curve (stress_dilatancy.csv); none for the reversing tests.
  std::optional<StressDilatancy> stressDilatancy;
  bool simpleShear = false;  // stressDilatancy's strain is gamma and it has no principal ratio
};
ShearReport reportShear(const RunConfig& config, const ShearResult& shear, Laboratory& lab, Json& summary);

// summary.json's shear_band: `detected`, the band's plane, thickness in d50, the void ratios inside
// and outside it in the wall box of `sim`, and its onset (eps1, and over `eps1AtPeak`). `detected`
// is null when the band was not looked for (`measured` false: no strain window closed, or a periodic
// cell), false when no band was found; every other value is null without a band.
Json shearBandJson(const std::optional<ShearBand>& band, bool measured, const Simulation& sim, double d50,
                   std::optional<double> onset, double eps1AtPeak);

// The shear band's onset: eps1 of the first window-closing record (Record::bandMeasured) from which
// every window to the end has a band (Record::bandInclinationDeg finite); null when the last window
// has none.
std::optional<double> bandOnset(const std::vector<Record>& records);

// The micromechanics columns of one record by name, null where not measurable, with its energy
// residual and eps1.
Json microJson(const Record& r, const std::vector<std::string>& names);

}  // namespace grainlab::lab

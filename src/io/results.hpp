#pragma once
// Results files: written whole to a temporary file and renamed, so a reader never sees half a file.
#include <filesystem>
#include <string>
#include <vector>

#include "lab/protocols.hpp"

namespace grainlab::io {

// Writes `content` to `path` through a temporary file beside it (removed again on any failure).
// Throws FileError naming the path and the system's reason.
void writeFileAtomic(const std::filesystem::path& path, const std::string& content);
// create_directories that throws FileError naming the folder and the system's reason.
void createDirectories(const std::filesystem::path& dir);

// Columns beyond the common ones that a test writes: the periodic cell's (eps1_log,
// stress_skew), simple shear's (gamma, tau) and true triaxial's (b).
struct TimeseriesColumns {
  bool periodic = false, simpleShear = false, trueTriaxial = false;
  // The micromechanical columns of the records (Laboratory::microColumnNames), after
  // energy_residual; their NaNs (not measurable) are written as empty fields.
  std::vector<std::string> micro;
  // Unload–reload loops configured: loop_phase (Record::loopPhase) after the micromechanics.
  bool loops = false;
  // Undrained tests: u (excess pore pressure); cyclic tests: cycle; oedometer and cyclic tests:
  // load_direction (+1 loading, -1 unloading).
  bool undrained = false, cyclic = false, reversing = false;
  // Stress paths: s and segment (Record::pathS, pathSegment).
  bool stressPath = false;
  // Cyclic simple shear: amplitude (1-based index into test.shear_strain_amplitudes).
  bool cyclicShear = false;
  bool gravity = false;  // sample.gravity given: the work of gravity, W_gravity
};
TimeseriesColumns timeseriesColumns(const lab::RunConfig& config);

// The time series as CSV (header + one row per record). Throws SimulationError on a non-finite
// value rather than writing it; only values that may be unmeasurable (b while sigma1 = sigma3,
// the energy residual before any external work, micromechanics without contacts) are written as
// empty fields (null).
std::string timeseriesCsv(const std::vector<lab::Record>& records, const TimeseriesColumns& columns = {});

}  // namespace grainlab::io

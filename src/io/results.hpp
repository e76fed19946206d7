#pragma once
// Results files: written whole to a temporary file and renamed, so a reader never sees half a file.
#include <filesystem>
#include <string>
#include <vector>

#include "lab/protocols.hpp"

namespace grainlab::io {

void writeFileAtomic(const std::filesystem::path& path, const std::string& content);

// The time series as CSV (header + one row per record). Throws SimulationError on a non-finite
// value rather than writing it.
std::string timeseriesCsv(const std::vector<lab::Record>& records);

}  // namespace grainlab::io

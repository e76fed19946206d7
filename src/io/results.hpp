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

// The time series as CSV (header + one row per record). Throws SimulationError on a non-finite
// value rather than writing it.
std::string timeseriesCsv(const std::vector<lab::Record>& records);

}  // namespace grainlab::io

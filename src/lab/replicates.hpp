#pragma once
// Statistics over replicate seeds of one case (`grainlab sweep --seeds N`, docs/interface.md).
// A value a seed could not measure (null in its summary) is left out of the statistics and counted
// apart, never taken as 0.
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace grainlab::lab {

struct ReplicateStats {
  std::size_t n = 0;      // seeds that measured the value
  std::size_t total = 0;  // seeds of the case (measured or not)
  double mean = std::numeric_limits<double>::quiet_NaN();
  double std = std::numeric_limits<double>::quiet_NaN();  // sample standard deviation (n - 1), n >= 2
  double min = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
};

ReplicateStats replicateStats(const std::vector<std::optional<double>>& values);

// How a table prints it: "mean ± std" for n >= 3, the range "[min, max]" for n = 2 (a standard
// deviation of two values says little), the value for n = 1, "null" for n = 0; " (n of total)"
// follows when some seeds did not measure it. `digits`: decimals.
std::string formatReplicates(const ReplicateStats& s, int digits);

}  // namespace grainlab::lab

#include "lab/replicates.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace grainlab::lab {

ReplicateStats replicateStats(const std::vector<std::optional<double>>& values) {
  ReplicateStats s;
  s.total = values.size();
  double sum = 0;
  for (const auto& v : values) {
    if (!v || !std::isfinite(*v)) continue;
    sum += *v;
    s.min = s.n == 0 ? *v : std::min(s.min, *v);
    s.max = s.n == 0 ? *v : std::max(s.max, *v);
    ++s.n;
  }
  if (s.n == 0) return s;
  s.mean = sum / static_cast<double>(s.n);
  if (s.n >= 2) {
    // Two passes: the deviations from the mean, not sum(x^2) - n mean^2 (cancellation).
    double ss = 0;
    for (const auto& v : values)
      if (v && std::isfinite(*v)) ss += (*v - s.mean) * (*v - s.mean);
    s.std = std::sqrt(ss / static_cast<double>(s.n - 1));
  }
  return s;
}

std::string formatReplicates(const ReplicateStats& s, int digits) {
  std::string text;
  if (s.n == 0) return "null";
  if (s.n == 1)
    text = fmt::format("{:.{}f}", s.mean, digits);
  else if (s.n == 2)
    text = fmt::format("[{:.{}f}, {:.{}f}]", s.min, digits, s.max, digits);
  else
    text = fmt::format("{:.{}f} ± {:.{}f}", s.mean, digits, s.std, digits);
  if (s.n < s.total) text += fmt::format(" ({} of {})", s.n, s.total);
  return text;
}

}  // namespace grainlab::lab

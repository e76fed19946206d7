#include "lab/grading.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <charconv>
#include <optional>
#include <string_view>

#include "core/errors.hpp"
#include "io/input_file.hpp"

namespace grainlab::lab {




std::vector<double> sampleDiameters(const GradingConfig& g, int n, Rng& rng) {
  std::vector<double> d(n);
  if (g.type == "uniform") {
    for (auto& v : d) v = rng.uniform(g.dMin, g.dMax);
  } else if (g.type == "list") {
    const std::vector<double>& list = g.list;
    if (list.empty())
      throw InputError(fmt::format("config error: sample.grading.file = {}: its diameters were not read with the config",
                                   io::quotedPath(g.file)));
    if (static_cast<int>(list.size()) == n) {
      d = list;
    } else {
      for (auto& v : d) v = list[static_cast<std::size_t>(rng.uniform() * list.size())];
    }
  } else {
    // Segment k carries mass fraction dP_k uniformly over [d_k, d_k+1]; its number weight is
    // dP_k/(d_k+1 - d_k) * integral of d^-3 = dP_k/(d_k+1 - d_k) * (d_k^-2 - d_k+1^-2)/2.
    const auto& D = g.diameters;
    const auto& P = g.passing;
    std::vector<double> cumulative(D.size(), 0.0);
    for (std::size_t k = 0; k + 1 < D.size(); ++k) {
      const double w = (P[k + 1] - P[k]) / (D[k + 1] - D[k]) *
                       0.5 * (1.0 / (D[k] * D[k]) - 1.0 / (D[k + 1] * D[k + 1]));
      cumulative[k + 1] = cumulative[k] + w;
    }
    for (auto& v : d) {
      const double u = rng.uniform() * cumulative.back();
      std::size_t k = std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin() - 1;
      k = std::min(k, D.size() - 2);
      while (cumulative[k + 1] == cumulative[k] && k + 2 < D.size()) ++k;  // skip empty segments
      const double a = 1.0 / (D[k] * D[k]), b = 1.0 / (D[k + 1] * D[k + 1]);
      const double s = rng.uniform();
      v = 1.0 / std::sqrt(a - s * (a - b));
    }
  }
  return d;
}

double percentPassingDiameter(const std::vector<double>& sorted, double percent) {
  double total = 0.0;
  for (double d : sorted) total += d * d * d;
  double acc = 0.0;
  const double target = percent / 100.0 * total;
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    const double m = sorted[i] * sorted[i] * sorted[i];
    if (acc + m >= target) {
      // Interpolate within the class of this grain, between the previous and this diameter.
      const double prev = i > 0 ? sorted[i - 1] : sorted[i];
      const double f = m > 0.0 ? (target - acc) / m : 1.0;
      return prev + f * (sorted[i] - prev);
    }
    acc += m;
  }
  return sorted.back();
}

GradingStats gradingStats(std::vector<double> d) {
  std::sort(d.begin(), d.end());
  GradingStats s;
  s.d10 = percentPassingDiameter(d, 10);
  s.d30 = percentPassingDiameter(d, 30);
  s.d50 = percentPassingDiameter(d, 50);
  s.d60 = percentPassingDiameter(d, 60);
  s.cu = s.d60 / s.d10;
  s.cc = s.d30 * s.d30 / (s.d10 * s.d60);
  s.dMin = d.front();
  s.dMax = d.back();
  return s;
}

}  // namespace grainlab::lab

#include "lab/sphericity.hpp"

#include <fmt/format.h>

#include <cfloat>
#include <numeric>
#include <sstream>

#include "core/errors.hpp"
#include "io/input_file.hpp"

namespace grainlab::lab {



void checkRollingFriction(const SphericityDistribution& d, double c, double k, const std::string& path,
                          const std::string& key) {
  auto check = [&](double psi, std::size_t row) {
    const double mu = rollingFrictionFromSphericity(psi, c, k);
    if (std::isfinite(mu) && (mu == 0.0 || mu >= DBL_MIN) && mu <= kMaxRollingFriction) return;
    throw InputError(fmt::format(
        "config error: {} = {}: line {}: sphericity {} gives mu_r = c psi^k = {} x {}^{} = {}; allowed: c and k "
        "(contact.sphericity.c, contact.sphericity.k) for which every grain's mu_r is a finite, normal number in [0, {}]",
        key, io::quotedPath(path), d.lines.at(row), psi, c, std::min(psi, 1.0), k, mu, kMaxRollingFriction));
  };
  for (std::size_t i = 0; i < d.values.size(); ++i) check(d.values[i], i);
  for (std::size_t i = 0; i < d.frequency.size(); ++i) {
    if (d.frequency[i] == 0.0) continue;  // a bin never drawn
    check(d.binLow[i], i);
    check(d.binHigh[i], i);
  }
}

std::vector<double> sampleSphericity(const SphericityDistribution& d, std::size_t n, Rng& rng) {
  std::vector<double> out(n);
  if (!d.isHistogram()) {
    for (auto& v : out) v = d.values[std::min(d.values.size() - 1, static_cast<std::size_t>(rng.uniform() * d.values.size()))];
    return out;
  }
  std::vector<double> cumulative(d.frequency.size());
  std::partial_sum(d.frequency.begin(), d.frequency.end(), cumulative.begin());
  for (auto& v : out) {
    const double u = rng.uniform() * cumulative.back();
    std::size_t b = std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin();
    b = std::min(b, cumulative.size() - 1);
    v = rng.uniform(d.binLow[b], d.binHigh[b]);
  }
  return out;
}

}  // namespace grainlab::lab

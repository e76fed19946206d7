#pragma once
// Per-grain rolling friction from true sphericity ([R], docs/physics.md §4.2): each grain draws its
// sphericity psi from a measured distribution (a list of values or a histogram), seeded; psi is
// capped at 1 and mu_r = c psi^k.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "lab/random.hpp"

namespace grainlab::lab {

struct SphericityDistribution {
  std::vector<double> values;            // a list of measured sphericities, or
  std::vector<double> binLow, binHigh;   // a histogram: bins [low, high) with
  std::vector<double> frequency;         // their (relative or absolute) frequencies
  std::vector<int> lines;                // the file's line of each value or bin
  bool isHistogram() const { return !frequency.empty(); }
};

// (The distribution is read with the config: io::readSphericityFile, io/list_files.hpp.)

// Draws n sphericities: from a list, uniformly among its values (a bootstrap of the measurement);
// from a histogram, a bin with probability proportional to its frequency, then uniformly inside.
std::vector<double> sampleSphericity(const SphericityDistribution& d, std::size_t n, Rng& rng);

// mu_r = c psi^k with psi capped at 1.
inline double rollingFrictionFromSphericity(double psi, double c, double k) {
  return c * std::pow(std::min(psi, 1.0), k);
}

// Largest rolling friction mu_r = c psi^k of a grain (as contact.rolling_friction allows).
inline constexpr double kMaxRollingFriction = 10.0;
// Refuses a distribution for which mu_r = c psi^k is not finite, not normal or above
// kMaxRollingFriction for some value (or bin end: mu_r is monotonic in psi), naming `key`, the file,
// the line, c and k.
void checkRollingFriction(const SphericityDistribution& d, double c, double k, const std::string& path,
                          const std::string& key);

}  // namespace grainlab::lab

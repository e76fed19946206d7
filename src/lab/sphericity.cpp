#include "lab/sphericity.hpp"

#include <fmt/format.h>

#include <cfloat>
#include <numeric>
#include <sstream>

#include "core/errors.hpp"
#include "io/input_file.hpp"

namespace grainlab::lab {

SphericityDistribution readSphericityFile(const std::string& path, const std::string& key) {
  const std::string subject = fmt::format("config error: {} = {}", key, io::quotedPath(path));
  std::istringstream in(io::readInputFile(path, subject, io::kMaxListFileBytes));
  auto fail = [&](int line, const std::string& what) {
    return InputError(fmt::format("{}: {}{}", subject, line > 0 ? fmt::format("line {}: ", line) : std::string(), what));
  };
  std::string line;
  int lineNo = 0;
  std::vector<std::string> header;
  while (header.empty() && std::getline(in, line)) {
    ++lineNo;
    if (!line.empty() && line[0] != '#') header = io::splitCsvLine(line);
  }
  auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    return it == header.end() ? -1 : static_cast<int>(it - header.begin());
  };
  const int psiCol = column("sphericity");
  const int lowCol = column("bin_low"), highCol = column("bin_high"), freqCol = column("frequency");
  if (psiCol < 0 && (lowCol < 0 || highCol < 0 || freqCol < 0))
    throw fail(lineNo, "expected a header with a column 'sphericity', or 'bin_low,bin_high,frequency'");
  SphericityDistribution d;
  while (std::getline(in, line)) {
    ++lineNo;
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r,") == std::string::npos) continue;
    const std::vector<std::string> f = io::splitCsvLine(line);
    auto number = [&](int col, const char* name) {
      if (col >= static_cast<int>(f.size())) throw fail(lineNo, fmt::format("missing {}", name));
      try {
        std::size_t used = 0;
        const double v = std::stod(f[col], &used);
        if (used != f[col].size() || !std::isfinite(v)) throw std::invalid_argument("");
        return v;
      } catch (const std::exception&) {
        throw fail(lineNo, fmt::format("{} \"{}\" is not a finite number", name, io::printable(f[col])));
      }
    };
    if (psiCol >= 0) {
      const double psi = number(psiCol, "sphericity");
      if (!(psi > 0.0) || psi < DBL_MIN) throw fail(lineNo, fmt::format("sphericity {} must be > 0 (a normal number, >= 2.2e-308)", psi));
      d.values.push_back(psi);
      d.lines.push_back(lineNo);
    } else {
      const double lo = number(lowCol, "bin_low"), hi = number(highCol, "bin_high"), fr = number(freqCol, "frequency");
      if (!(lo >= DBL_MIN) || !(hi > lo))
        throw fail(lineNo, fmt::format("bin [{}, {}) must satisfy 0 < bin_low < bin_high (bin_low a normal number >= 2.2e-308)", lo, hi));
      if (fr < 0.0 || (fr > 0.0 && fr < DBL_MIN)) throw fail(lineNo, fmt::format("frequency {} must be >= 0 (0 or a normal number)", fr));
      d.lines.push_back(lineNo);
      d.binLow.push_back(lo);
      d.binHigh.push_back(hi);
      d.frequency.push_back(fr);
    }
  }
  if (d.values.empty() && d.frequency.empty()) throw fail(0, "no data rows");
  if (d.isHistogram() && std::accumulate(d.frequency.begin(), d.frequency.end(), 0.0) <= 0.0)
    throw fail(0, "all frequencies are zero");
  return d;
}

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

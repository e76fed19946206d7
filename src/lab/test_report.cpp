#include "lab/test_report.hpp"

#include <algorithm>
#include <cmath>

namespace grainlab::lab {

UndrainedSummary undrainedSummary(const std::vector<Record>& records, double p0, double ruLimit, double volumeDriftMax) {
  UndrainedSummary s;
  s.volumeDriftMax = volumeDriftMax;
  if (records.empty()) return s;
  std::size_t iMin = 0;
  s.uMax = s.uMin = records[0].u;
  for (std::size_t i = 0; i < records.size(); ++i) {
    s.uMax = std::max(s.uMax, records[i].u);
    s.uMin = std::min(s.uMin, records[i].u);
    if (records[i].p < records[iMin].p) iMin = i;
  }
  s.pMin = records[iMin].p;
  s.liquefied = s.pMin <= (1.0 - ruLimit) * p0;
  if (iMin > 0 && iMin + 1 < records.size()) {
    s.qAtPhaseTransformation = records[iMin].q;
    s.eps1AtPhaseTransformation = records[iMin].eps1;
  }
  return s;
}

namespace {
// Least-squares slope of y against x; nullopt with fewer than 3 points or no spread in x.
std::optional<double> slope(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = x.size();
  if (n < 3) return std::nullopt;
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= static_cast<double>(n);
  my /= static_cast<double>(n);
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  if (!(sxx > 0.0)) return std::nullopt;
  return sxy / sxx;
}
}  // namespace

OedometerSummary oedometerSummary(const std::vector<Record>& records, double p0) {
  OedometerSummary s;
  for (const Record& r : records) s.sigmaVMax = std::max(s.sigmaVMax, r.sigma1);
  if (!(s.sigmaVMax > p0)) return s;
  const double from = std::sqrt(p0 * s.sigmaVMax);
  std::vector<double> logLoad, eLoad, logUnload, eUnload;
  double kSum = 0.0;
  bool unloading = false;
  for (const Record& r : records) {
    if (r.loadDirection < 0) unloading = true;
    if (!(r.sigma1 > 0.0)) continue;
    const double k = 0.5 * (r.sigma2 + r.sigma3) / r.sigma1;
    if (!unloading && r.sigma1 >= from) {
      logLoad.push_back(std::log10(r.sigma1));
      eLoad.push_back(r.e);
      kSum += k;
    } else if (unloading) {
      logUnload.push_back(std::log10(r.sigma1));
      eUnload.push_back(r.e);
      s.k0Unloading = k;
    }
  }
  s.loadingRecords = logLoad.size();
  s.unloadingRecords = logUnload.size();
  if (!logLoad.empty()) s.k0 = kSum / static_cast<double>(logLoad.size());
  if (const auto c = slope(logLoad, eLoad)) s.cc = -*c;
  if (const auto c = slope(logUnload, eUnload)) s.cs = -*c;
  return s;
}

CyclicSummary cyclicSummary(const ProtocolState& state) {
  CyclicSummary s;
  if (state.liquefiedCycles >= 0.0) s.cyclesToLiquefaction = state.liquefiedCycles;
  s.ruMax = state.ruMax;
  s.cycles = 0.5 * static_cast<double>(state.halfCycles);
  s.doubleAmplitudeMax = state.doubleAmplitude;
  return s;
}

}  // namespace grainlab::lab

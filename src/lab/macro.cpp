#include "lab/macro.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/types.hpp"
#include "lab/moduli.hpp"

namespace grainlab::lab {

double mobilisedFrictionDeg(double s1, double s3) {
  const double sum = s1 + s3;
  if (!(sum > 0.0)) return 0.0;
  return radToDeg(std::asin(std::clamp((s1 - s3) / sum, -1.0, 1.0)));
}

double dilatancyAngleDeg(double r) {
  return radToDeg(std::asin(std::clamp(-r / (2.0 - r), -1.0, 1.0)));
}

double dilatancyAngleTanDeg(double r) { return radToDeg(std::atan(-r)); }

double slope(const std::vector<double>& x, const std::vector<double>& y, std::size_t b, std::size_t e) {
  const double n = static_cast<double>(e - b);
  if (e <= b + 1) return 0.0;
  double mx = 0.0, my = 0.0;
  for (std::size_t i = b; i < e; ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= n;
  my /= n;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = b; i < e; ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  return sxx > 0.0 ? sxy / sxx : 0.0;
}

double autoCsWindow(double finalStrain) { return std::max(0.05, 0.25 * finalStrain); }

SteadyState steadyState(const std::vector<double>& eps, const std::vector<double>& eta,
                        const std::vector<double>& epsV, const std::vector<double>& e,
                        const std::vector<double>& p, const MacroSettings& s) {
  SteadyState out;
  const std::size_t n = eps.size();
  if (eta.size() != n || epsV.size() != n || e.size() != n || p.size() != n) return out;
  if (n < s.csMinRecords || eps.back() - eps.front() < s.csWindow) return out;
  auto mean = [](const std::vector<double>& v, std::size_t b, std::size_t end) {
    double sum = 0.0;
    for (std::size_t i = b; i < end; ++i) sum += v[i];
    return end > b ? sum / static_cast<double>(end - b) : 0.0;
  };
  // Windows ending at record k: [first record with eps >= eps_k - window, k].
  std::vector<char> steady(n, 0), evaluated(n, 0);
  std::size_t lo = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (eps[k] - eps.front() < s.csWindow) continue;
    while (lo < k && eps[lo] < eps[k] - s.csWindow) ++lo;
    const std::size_t b = lo, end = k + 1;
    if (end - b < s.csMinRecords) continue;
    evaluated[k] = 1;
    const double rEta = slope(eps, eta, b, end), rV = slope(eps, epsV, b, end), rE = slope(eps, e, b, end);
    steady[k] = std::abs(rEta) <= s.csMaxStressRatioRate && std::abs(rV) <= s.csMaxVolumetricRate &&
                std::abs(rE) <= s.csMaxVoidRatioRate;
    if (k + 1 == n) {
      out.evaluated = true;
      out.endStressRatio = mean(eta, b, end);
      out.endVoidRatio = mean(e, b, end);
      out.endMeanStress = mean(p, b, end);
      out.endStressRatioRate = rEta;
      out.endVolumetricRate = rV;
      out.endVoidRatioRate = rE;
    }
  }
  if (!out.evaluated || !steady[n - 1]) return out;
  // The steady run to the end: back from the last record while every evaluated window is steady.
  std::size_t first = n - 1;
  while (first > 0 && evaluated[first - 1] && steady[first - 1]) --first;
  out.reached = true;
  out.reachedAt = eps[first];
  // The critical-state values: the means from eps* to the end (every window ending there is steady),
  // or of the last window when fewer than csMinRecords records follow eps*.
  std::size_t b = first;
  if (n - b < s.csMinRecords) {
    out.stressRatio = out.endStressRatio;
    out.voidRatio = out.endVoidRatio;
    out.meanStress = out.endMeanStress;
    return out;
  }
  out.stressRatio = mean(eta, b, n);
  out.voidRatio = mean(e, b, n);
  out.meanStress = mean(p, b, n);
  return out;
}

namespace {

// Means of the friction angle, the stress ratio and the void ratio over eps1 >= m.residualFrom
// (the critical-state window), written into m.
void residualMeans(const TriaxialCurves& c, const std::vector<double>& phi, const std::vector<double>& ratio,
                   MacroParameters& m) {
  double sumPhi = 0.0, sumRatio = 0.0, sumE = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < c.eps1.size(); ++i) {
    if (c.eps1[i] < m.residualFrom) continue;
    sumPhi += phi[i];
    sumRatio += ratio[i];
    sumE += c.voidRatio.empty() ? 0.0 : c.voidRatio[i];
    ++count;
  }
  if (count > 0) {
    m.phiResDeg = sumPhi / count;
    m.residualStressRatio = sumRatio / count;
    m.residualVoidRatio = sumE / count;
  }
}

// Largest dilatancy angle over centred windows of +-halfWindow in eps1: the least-squares slope of
// eps_v on eps1 in each window (at least 3 points) is turned into an angle by psiOf, which returns
// nothing where the slope has no angle.
template <class PsiOf>
void maxDilatancy(const TriaxialCurves& c, double halfWindow, PsiOf psiOf, MacroParameters& m) {
  const std::size_t n = c.eps1.size();
  std::size_t lo = 0, hi = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (lo < n && c.eps1[lo] < c.eps1[i] - halfWindow) ++lo;
    while (hi < n && c.eps1[hi] <= c.eps1[i] + halfWindow) ++hi;
    if (hi - lo < 3) continue;
    const std::optional<double> psi = psiOf(slope(c.eps1, c.epsV, lo, hi));
    if (psi && (!m.psiMaxDeg || *psi > *m.psiMaxDeg)) {
      m.psiMaxDeg = *psi;
      m.eps1AtPsiMax = c.eps1[i];
    }
  }
}

}  // namespace

StressDilatancy stressDilatancy(const TriaxialCurves& c, bool simpleShear, double halfWindow) {
  StressDilatancy out;
  const std::size_t n = c.eps1.size();
  if (c.epsV.size() != n || c.sigma1.size() != n || (simpleShear ? c.shearStress.size() : c.sigma3.size()) != n)
    return out;
  std::size_t lo = 0, hi = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (lo < n && c.eps1[lo] < c.eps1[i] - halfWindow) ++lo;
    while (hi < n && c.eps1[hi] <= c.eps1[i] + halfWindow) ++hi;
    if (hi - lo < 3) continue;
    double eta = 0.0;
    if (simpleShear) {
      if (!(c.sigma1[i] > 0.0)) continue;
      eta = c.shearStress[i] / c.sigma1[i];
    } else {
      const double q = c.sigma1[i] - c.sigma3[i], p = (c.sigma1[i] + 2.0 * c.sigma3[i]) / 3.0;
      if (!(p > 0.0) || !(c.sigma3[i] > 0.0)) continue;
      eta = q / p;
      out.principalRatio.push_back(c.sigma1[i] / c.sigma3[i]);
    }
    out.strain.push_back(c.eps1[i]);
    out.dilatancy.push_back(-slope(c.eps1, c.epsV, lo, hi));
    out.stressRatio.push_back(eta);
  }
  return out;
}

MacroParameters computeMacro(const TriaxialCurves& c, const MacroSettings& s) {
  MacroParameters m;
  const std::size_t n = c.eps1.size();
  if (n < 2) return m;
  std::vector<double> q(n), p(n), phi(n);
  for (std::size_t i = 0; i < n; ++i) {
    q[i] = c.sigma1[i] - c.sigma3[i];
    p[i] = (c.sigma1[i] + 2.0 * c.sigma3[i]) / 3.0;
    phi[i] = mobilisedFrictionDeg(c.sigma1[i], c.sigma3[i]);
  }
  const std::size_t peak = std::max_element(phi.begin(), phi.end()) - phi.begin();
  m.phiPeakDeg = phi[peak];
  m.eps1AtPeak = c.eps1[peak];
  m.qPeak = *std::max_element(q.begin(), q.end());

  std::vector<double> ratio(n);
  for (std::size_t i = 0; i < n; ++i) ratio[i] = p[i] > 0.0 ? q[i] / p[i] : 0.0;
  m.residualFrom = (1.0 - s.residualFraction) * c.eps1.back();
  residualMeans(c, phi, ratio, m);

  // Dilatancy: sin psi = -r/(2 - r) of the slope r = d eps_v / d eps1 is only defined while the
  // lateral strain rate is extensional or small (r < 2); a sudden collapse (eps_v growing faster
  // than the axial strain) has no dilatancy angle.
  maxDilatancy(c, s.dilatancyHalfWindow,
               [](double rate) -> std::optional<double> {
                 if (rate >= 1.0) return std::nullopt;
                 return dilatancyAngleDeg(rate);
               },
               m);
  {
    // The same windows in the other convention, tan psi = D (defined for any rate).
    MacroParameters t;
    maxDilatancy(c, s.dilatancyHalfWindow,
                 [](double rate) -> std::optional<double> { return dilatancyAngleTanDeg(rate); }, t);
    m.psiMaxTanDeg = t.psiMaxDeg;
  }
  m.e50 = secantE50(c.eps1, q);
  m.steady = steadyState(c.eps1, ratio, c.epsV, c.voidRatio, p, s);
  return m;
}

MacroParameters computeSimpleShearMacro(const TriaxialCurves& c, const MacroSettings& s) {
  MacroParameters m;
  const std::size_t n = c.eps1.size();
  if (n < 2 || c.shearStress.size() != n) return m;
  std::vector<double> ratio(n), phi(n);
  for (std::size_t i = 0; i < n; ++i) {
    ratio[i] = c.sigma1[i] > 0.0 ? c.shearStress[i] / c.sigma1[i] : 0.0;
    phi[i] = radToDeg(std::atan(ratio[i]));
  }
  const std::size_t peak = std::max_element(phi.begin(), phi.end()) - phi.begin();
  m.phiPeakDeg = phi[peak];
  m.eps1AtPeak = c.eps1[peak];
  m.qPeak = c.shearStress[peak];
  m.residualFrom = (1.0 - s.residualFraction) * c.eps1.back();
  residualMeans(c, phi, ratio, m);
  // Simple shear: tan psi = -d eps_v / d gamma.
  maxDilatancy(c, s.dilatancyHalfWindow,
               [](double rate) -> std::optional<double> { return dilatancyAngleTanDeg(rate); }, m);
  m.psiMaxTanDeg = m.psiMaxDeg;  // simple shear's psi is the tan definition already
  m.steady = steadyState(c.eps1, ratio, c.epsV, c.voidRatio, c.sigma1, s);
  std::size_t end = 0;
  while (end < n && c.eps1[end] <= s.elasticWindow) ++end;
  end = std::max<std::size_t>(end, std::min<std::size_t>(n, 3));
  m.shearModulus = slope(c.eps1, c.shearStress, 0, end);
  return m;
}

}  // namespace grainlab::lab

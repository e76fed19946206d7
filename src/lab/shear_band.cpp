// The shear band's plane and thickness (lab/shear_band.hpp).
#include "lab/shear_band.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace grainlab::lab {

namespace {
double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The least-squares plane through points: their centroid and the eigen-decomposition of their
// covariance (eigenvalues increasing; the first eigenvector is the plane's normal).
struct PlaneFit {
  Vec3 centre;
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  bool ok() const { return eig.info() == Eigen::Success && eig.eigenvalues()(1) > 0.0; }
};
PlaneFit fitPlane(const std::vector<Vec3>& points) {
  Vec3 centre = Vec3::Zero();
  for (const Vec3& x : points) centre += x;
  centre /= static_cast<double>(points.size());
  Mat3 cov = Mat3::Zero();
  for (const Vec3& x : points) cov += (x - centre) * (x - centre).transpose();
  cov /= static_cast<double>(points.size());
  return {centre, Eigen::SelfAdjointEigenSolver<Mat3>(cov)};
}
}  // namespace

std::optional<ShearBand> findShearBand(const std::vector<Vec3>& position, const std::vector<double>& strain,
                                       const std::vector<double>& inBand, const std::vector<char>& active,
                                       const ShearBandSettings& settings) {
  const std::size_t n = position.size();
  if (strain.size() != n || inBand.size() != n || (!active.empty() && active.size() != n) ||
      !(settings.binWidth > 0.0))
    return std::nullopt;
  auto counts = [&](std::size_t i) { return active.empty() || active[i]; };

  // 1. The flagged load-bearing grains, and the others' strain (the background).
  std::vector<std::size_t> band;
  std::vector<double> outside;
  std::size_t counted = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!counts(i) || !std::isfinite(strain[i])) continue;
    ++counted;
    if (inBand[i] > 0.5)
      band.push_back(i);
    else
      outside.push_back(strain[i]);
  }
  if (band.size() < settings.minGrains || outside.empty() ||
      static_cast<double>(band.size()) > settings.maxFraction * static_cast<double>(counted))
    return std::nullopt;

  // 2. The plane: centroid and covariance of the flagged grains.
  std::vector<Vec3> flagged;
  for (std::size_t i : band) flagged.push_back(position[i]);
  const PlaneFit guess = fitPlane(flagged);
  if (!guess.ok()) return std::nullopt;
  Vec3 centre = guess.centre;
  ShearBand b;
  b.flatness = guess.eig.eigenvalues()(0) / guess.eig.eigenvalues()(1);
  if (!(b.flatness <= settings.maxFlatness)) return std::nullopt;
  // The covariance's normal is biased where the boundary clips the band obliquely (a slab cut by
  // vertical walls is a parallelogram, whose thickness and length directions correlate). The
  // mid-plane is refined from the band's local mid-points instead: the flagged grains are binned in
  // columns along the normal (2 bin widths square in the plane), each full column's centroid lies
  // on the mid-plane, and a plane fitted to those centroids gives the next normal. Columns with
  // fewer than 0.85 of the median count (clipped at the boundary) are left out.
  Vec3 normal = guess.eig.eigenvectors().col(0).normalized();
  for (int iteration = 0; iteration < 30; ++iteration) {
    const Vec3 e1 = (std::abs(normal.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(normal).normalized();
    const Vec3 e2 = normal.cross(e1);
    const double h = 2.0 * settings.binWidth;
    std::map<std::pair<long, long>, std::pair<Vec3, std::size_t>> columns;
    for (const Vec3& x : flagged) {
      const Vec3 d = x - centre;
      const std::pair<long, long> key{static_cast<long>(std::floor(e1.dot(d) / h)),
                                      static_cast<long>(std::floor(e2.dot(d) / h))};
      auto& c = columns.try_emplace(key, Vec3::Zero(), std::size_t{0}).first->second;
      c.first += x;
      ++c.second;
    }
    std::vector<double> sizes;
    for (const auto& [key, c] : columns) sizes.push_back(static_cast<double>(c.second));
    const double least = std::max(3.0, 0.85 * median(sizes));
    std::vector<Vec3> mid;
    for (const auto& [key, c] : columns)
      if (static_cast<double>(c.second) >= least) mid.push_back(c.first / static_cast<double>(c.second));
    if (mid.size() < 3) break;
    const PlaneFit plane = fitPlane(mid);
    if (!plane.ok()) break;
    Vec3 next = plane.eig.eigenvectors().col(0).normalized();
    if (next.dot(normal) < 0.0) next = -next;
    const bool converged = next.dot(normal) > 1.0 - 1e-12;
    normal = next;
    centre = plane.centre;
    if (converged) break;
  }
  b.normal = normal.z() < 0.0 ? Vec3(-normal) : normal;
  b.centre = centre;
  b.grains = band.size();
  b.inclinationDeg = radToDeg(std::acos(std::min(1.0, std::abs(b.normal.z()))));

  // 3. The profile of eq across the plane, in bins of binWidth centred on the mid-plane.
  double sMin = 0.0, sMax = 0.0;
  std::vector<double> s(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!counts(i) || !std::isfinite(strain[i])) continue;
    s[i] = b.normal.dot(position[i] - centre);
    sMin = std::min(sMin, s[i]);
    sMax = std::max(sMax, s[i]);
  }
  const double w = settings.binWidth;
  const long first = static_cast<long>(std::floor(sMin / w - 0.5)), last = static_cast<long>(std::floor(sMax / w + 0.5));
  const std::size_t bins = static_cast<std::size_t>(last - first + 1);
  std::vector<double> sum(bins, 0.0);
  std::vector<std::size_t> count(bins, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!counts(i) || !std::isfinite(strain[i])) continue;
    const long k = static_cast<long>(std::floor(s[i] / w + 0.5)) - first;  // bin k: centre (k + first) w
    sum[static_cast<std::size_t>(k)] += strain[i];
    ++count[static_cast<std::size_t>(k)];
  }
  std::vector<double> profile(bins, std::nan(""));
  for (std::size_t k = 0; k < bins; ++k)
    if (count[k] >= 3) profile[k] = sum[k] / static_cast<double>(count[k]);
  std::size_t peak = bins;
  for (std::size_t k = 0; k < bins; ++k)
    if (std::isfinite(profile[k]) && (peak == bins || profile[k] > profile[peak])) peak = k;
  if (peak == bins) return std::nullopt;
  b.backgroundStrain = median(outside);
  b.peakStrain = profile[peak];
  if (!(b.peakStrain >= settings.minContrast * b.backgroundStrain) || !(b.peakStrain > b.backgroundStrain))
    return std::nullopt;
  const double half = 0.5 * (b.peakStrain + b.backgroundStrain);
  // Walk out from the peak to where the profile falls below half height; the crossing lies between
  // the last bin above and the first below (linear interpolation). A band whose profile does not
  // fall to half height inside the sample has no measured width.
  auto edge = [&](int dir) -> std::optional<double> {
    long k = static_cast<long>(peak);
    long inside = k;
    for (;;) {
      k += dir;
      if (k < 0 || k >= static_cast<long>(bins)) return std::nullopt;
      if (!std::isfinite(profile[static_cast<std::size_t>(k)])) continue;
      if (profile[static_cast<std::size_t>(k)] < half) break;
      inside = k;
    }
    const double a = profile[static_cast<std::size_t>(inside)], c = profile[static_cast<std::size_t>(k)];
    const double t = (a - half) / (a - c);  // in (0, 1]
    return (static_cast<double>(inside) + t * static_cast<double>(k - inside) + static_cast<double>(first)) * w;
  };
  const std::optional<double> lo = edge(-1), hi = edge(+1);
  if (!lo || !hi) return std::nullopt;
  b.thickness = *hi - *lo;
  return b;
}

std::optional<BandVoidRatios> bandVoidRatios(const ShearBand& band, const std::vector<Vec3>& position,
                                             const std::vector<Vec3>& semiAxes, const Vec3& lo, const Vec3& hi,
                                             const std::function<bool(const Vec3&)>& inSample) {
  if (position.size() != semiAxes.size() || !(band.thickness > 0.0) || !((hi - lo).minCoeff() > 0.0))
    return std::nullopt;
  const double h = 0.5 * band.thickness;
  // The volume of a sphere of radius r below a plane at height t above its lowest point.
  auto below = [](double r, double t) {
    t = std::clamp(t, 0.0, 2.0 * r);
    return kPi * t * t * (3.0 * r - t) / 3.0;
  };
  double solidIn = 0.0, solid = 0.0;
  for (std::size_t i = 0; i < position.size(); ++i) {
    const Vec3& a = semiAxes[i];
    const double r = std::cbrt(a[0] * a[1] * a[2]);
    const double s = band.normal.dot(position[i] - band.centre);
    solid += 4.0 / 3.0 * kPi * a[0] * a[1] * a[2];
    solidIn += below(r, h - (s - r)) - below(r, -h - (s - r));
  }
  constexpr int kGrid = 128;
  const Vec3 step = (hi - lo) / kGrid;
  long inside = 0, sample = 0;
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j)
      for (int k = 0; k < kGrid; ++k) {
        const Vec3 x = lo + Vec3((i + 0.5) * step.x(), (j + 0.5) * step.y(), (k + 0.5) * step.z());
        if (inSample && !inSample(x)) continue;
        ++sample;
        inside += std::abs(band.normal.dot(x - band.centre)) <= h;
      }
  const double cell = (hi - lo).prod() / (static_cast<double>(kGrid) * kGrid * kGrid);
  const double volume = inSample ? cell * static_cast<double>(sample) : (hi - lo).prod();
  const double slab = inSample ? cell * static_cast<double>(inside)
                               : volume * static_cast<double>(inside) / (static_cast<double>(kGrid) * kGrid * kGrid);
  if (!(solidIn > 0.0) || !(solid - solidIn > 0.0)) return std::nullopt;
  return BandVoidRatios{slab / solidIn - 1.0, (volume - slab) / (solid - solidIn) - 1.0};
}

}  // namespace grainlab::lab

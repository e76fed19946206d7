#include "lab/kinematics.hpp"

#include <limits>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/spatial_grid.hpp"

namespace grainlab::lab {

double equivalentShearStrain(const Mat3& strain) {
  const Mat3 dev = strain - strain.trace() / 3.0 * Mat3::Identity();
  return std::sqrt(2.0 / 3.0 * dev.cwiseProduct(dev).sum());
}

GrainKinematics grainKinematics(const Simulation& sim, const GrainRecords& records, const Mat3& boxStrain,
                                double radius, double bandFactor, const std::vector<char>& active) {
  const Particles& P = sim.particles;
  const std::size_t n = P.size();
  const bool periodic = sim.boundary == Boundary::Periodic;
  GrainKinematics k;
  k.displacement.resize(n);
  k.rotationDeg.resize(n);
  k.localShearStrain.assign(n, 0.0);
  k.inBand.assign(n, 0.0);
  k.boxShearStrain = equivalentShearStrain(boxStrain);
  k.active = active;
  for (std::size_t i = 0; i < n; ++i) {
    k.displacement[i] = records.displacement(sim, i);
    k.rotationDeg[i] = radToDeg(records.rotationAngle(P, i));
  }

  // Neighbours in the reference configuration from the spatial grid. In a wall box: cells of side
  // `radius` at floor(x / radius). In a periodic cell: reference positions wrapped into the
  // reference cell (x - H_ref k), cells in its scaled coordinates, each at least `radius` wide.
  const Mat3& hRef = records.referenceCell;
  const Mat3 hRefInverse = periodic ? Mat3(hRef.inverse()) : Mat3::Identity();
  std::vector<Vec3> ref = records.referencePosition;
  std::vector<std::array<int, 3>> wrapped(n, {0, 0, 0});
  SpatialGrid grid;
  SpatialGrid::Cell dims{}, offset{};
  std::vector<SpatialGrid::Cell> cellOf(n);
  if (periodic) {
    for (int a = 0; a < 3; ++a)
      dims[a] = SpatialGrid::cellsAlong(1.0 / hRefInverse.row(a).norm(), radius);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 s = hRefInverse * ref[i];
      for (int a = 0; a < 3; ++a) wrapped[i][a] = static_cast<int>(std::floor(s[a]));
      const Vec3 sw = s - Vec3(wrapped[i][0], wrapped[i][1], wrapped[i][2]);
      ref[i] -= hRef * Vec3(wrapped[i][0], wrapped[i][1], wrapped[i][2]);
      for (int a = 0; a < 3; ++a) cellOf[i][a] = SpatialGrid::coordinate(sw[a] * dims[a], 0.0, 1.0, dims[a]);
    }
  } else {
    std::array<int, 3> lo{1 << 30, 1 << 30, 1 << 30}, hi{-(1 << 30), -(1 << 30), -(1 << 30)};
    for (std::size_t i = 0; i < n; ++i)
      for (int a = 0; a < 3; ++a) {
        const int c = static_cast<int>(std::floor(ref[i][a] / radius));
        lo[a] = std::min(lo[a], c);
        hi[a] = std::max(hi[a], c);
      }
    for (int a = 0; a < 3; ++a) {
      offset[a] = lo[a];
      dims[a] = std::clamp(hi[a] - lo[a] + 1, 1, SpatialGrid::kMaxDim);
    }
    for (std::size_t i = 0; i < n; ++i)
      for (int a = 0; a < 3; ++a) cellOf[i][a] = SpatialGrid::coordinate(ref[i][a], 0.0, radius, dims[a], offset[a]);
  }
  grid.reset(dims);
  for (std::size_t i = 0; i < n; ++i) grid.insert(static_cast<std::uint32_t>(i), cellOf[i]);
  const Mat3 cellChange = sim.cell.h - hRef;

#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    Mat3 a = Mat3::Zero(), b = Mat3::Zero();  // sum du dx^T, sum dx dx^T
    int count = 0;
    auto add = [&](std::uint32_t j, const Vec3& branch, const Vec3& du) {
      if (j == i || branch.squaredNorm() > radius * radius) return;
      a += du * branch.transpose();
      b += branch * branch.transpose();
      ++count;
    };
    if (periodic) {
      grid.forEachAroundPeriodic(cellOf[i], [&](std::uint32_t j, const SpatialGrid::Cell& s) {
        const Vec3 shift(s[0], s[1], s[2]);
        // The image's lattice offset in the unwrapped frame, m = s - k_j + k_i.
        const Vec3 m = shift - Vec3(wrapped[j][0], wrapped[j][1], wrapped[j][2]) +
                       Vec3(wrapped[i][0], wrapped[i][1], wrapped[i][2]);
        add(j, ref[j] + hRef * shift - ref[i], k.displacement[j] - k.displacement[i] + cellChange * m);
      });
    } else {
      grid.forEachAround(cellOf[i], [&](std::uint32_t j) {
        add(j, ref[j] - ref[i], k.displacement[j] - k.displacement[i]);
      });
    }
    // Fewer than 4 neighbours (or all in a plane) do not determine a 3-D gradient.
    if (count < 4 || std::abs(b.determinant()) < 1e-12 * std::pow(b.trace() / 3.0, 3)) {
      k.localShearStrain[i] = k.boxShearStrain;
      continue;
    }
    const Mat3 f = Mat3::Identity() + a * b.inverse();
    k.localShearStrain[i] = equivalentShearStrain(0.5 * (f.transpose() * f - Mat3::Identity()));
  }

  double sumAll = 0.0, sumBand = 0.0, sumOut = 0.0;
  std::size_t band = 0, counted = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const bool in = k.boxShearStrain > 0.0 && k.localShearStrain[i] >= bandFactor * k.boxShearStrain;
    k.inBand[i] = in ? 1.0 : 0.0;
    if (!active.empty() && !active[i]) continue;
    ++counted;
    sumAll += k.rotationDeg[i];
    (in ? sumBand : sumOut) += k.rotationDeg[i];
    band += in;
  }
  // A mean over no grain is not measured (NaN: null in the summary, an empty field in the time
  // series), and without a homogeneous strain there is no band criterion at all.
  const double none = std::numeric_limits<double>::quiet_NaN();
  const bool classified = k.boxShearStrain > 0.0 && counted > 0;
  k.rotationMeanDeg = counted ? sumAll / counted : none;
  k.rotationBandMeanDeg = classified && band ? sumBand / band : none;
  k.rotationOutsideMeanDeg = classified && counted > band ? sumOut / (counted - band) : none;
  k.bandFraction = classified ? static_cast<double>(band) / counted : none;
  // The spread of the rotations about each mean (population standard deviation; NaN below two grains).
  double squaresBand = 0.0, squaresOut = 0.0;
  for (std::size_t i = 0; i < n && classified; ++i) {
    if (!active.empty() && !active[i]) continue;
    if (k.inBand[i] > 0.5)
      squaresBand += (k.rotationDeg[i] - k.rotationBandMeanDeg) * (k.rotationDeg[i] - k.rotationBandMeanDeg);
    else
      squaresOut += (k.rotationDeg[i] - k.rotationOutsideMeanDeg) * (k.rotationDeg[i] - k.rotationOutsideMeanDeg);
  }
  k.rotationBandStdDeg = classified && band >= 2 ? std::sqrt(squaresBand / band) : none;
  k.rotationOutsideStdDeg = classified && counted - band >= 2 ? std::sqrt(squaresOut / (counted - band)) : none;
  return k;
}

}  // namespace grainlab::lab

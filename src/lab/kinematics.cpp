#include "lab/kinematics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

namespace grainlab::lab {

double equivalentShearStrain(const Mat3& strain) {
  const Mat3 dev = strain - strain.trace() / 3.0 * Mat3::Identity();
  return std::sqrt(2.0 / 3.0 * dev.cwiseProduct(dev).sum());
}

GrainKinematics grainKinematics(const Particles& P, const std::vector<Vec3>& ref, const Mat3& boxStrain,
                                double radius, double bandFactor, const std::vector<char>& active) {
  const std::size_t n = P.size();
  GrainKinematics k;
  k.displacement.resize(n);
  k.rotationDeg.resize(n);
  k.localShearStrain.assign(n, 0.0);
  k.inBand.assign(n, 0.0);
  k.boxShearStrain = equivalentShearStrain(boxStrain);
  for (std::size_t i = 0; i < n; ++i) {
    k.displacement[i] = P.position[i] - ref[i];
    k.rotationDeg[i] = radToDeg(P.rotationAngle(i));
  }

  // Neighbours in the reference configuration from a hash grid of cells of side `radius`.
  auto cellOf = [&](const Vec3& x) {
    return std::array<long, 3>{static_cast<long>(std::floor(x[0] / radius)),
                               static_cast<long>(std::floor(x[1] / radius)),
                               static_cast<long>(std::floor(x[2] / radius))};
  };
  auto key = [](long x, long y, long z) {
    return (static_cast<std::uint64_t>(x & 0x1fffff) << 42) | (static_cast<std::uint64_t>(y & 0x1fffff) << 21) |
           static_cast<std::uint64_t>(z & 0x1fffff);
  };
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> grid;
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = cellOf(ref[i]);
    grid[key(c[0], c[1], c[2])].push_back(static_cast<std::uint32_t>(i));
  }
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = cellOf(ref[i]);
    Mat3 a = Mat3::Zero(), b = Mat3::Zero();  // sum du dx^T, sum dx dx^T
    int count = 0;
    for (long dz = -1; dz <= 1; ++dz)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dx = -1; dx <= 1; ++dx) {
          const auto it = grid.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
          if (it == grid.end()) continue;
          for (std::uint32_t j : it->second) {
            if (j == i) continue;
            const Vec3 branch = ref[j] - ref[i];
            if (branch.squaredNorm() > radius * radius) continue;
            const Vec3 du = k.displacement[j] - k.displacement[i];
            a += du * branch.transpose();
            b += branch * branch.transpose();
            ++count;
          }
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
  k.rotationMeanDeg = counted ? sumAll / counted : 0.0;
  k.rotationBandMeanDeg = band ? sumBand / band : 0.0;
  k.rotationOutsideMeanDeg = counted > band ? sumOut / (counted - band) : 0.0;
  k.bandFraction = counted ? static_cast<double>(band) / counted : 0.0;
  return k;
}

}  // namespace grainlab::lab

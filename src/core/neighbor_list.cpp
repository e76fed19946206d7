#include "core/neighbor_list.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "core/state_io.hpp"

namespace grainlab {

namespace {

std::uint64_t pairKey(std::uint32_t a, std::uint32_t b) {
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

// Carries history from (oldKeys, oldHist) to the entries of newKeys with equal keys; both sorted.
void mergeHistory(const std::vector<std::uint64_t>& oldKeys,
                  const std::vector<contact::ContactHistory>& oldHist,
                  const std::vector<std::uint64_t>& newKeys,
                  std::vector<contact::ContactHistory>& newHist) {
  newHist.assign(newKeys.size(), contact::ContactHistory{});
  std::size_t o = 0;
  for (std::size_t n = 0; n < newKeys.size(); ++n) {
    while (o < oldKeys.size() && oldKeys[o] < newKeys[n]) ++o;
    if (o < oldKeys.size() && oldKeys[o] == newKeys[n]) newHist[n] = oldHist[o];
  }
}

}  // namespace

void NeighborList::saveState(std::ostream& out) const {
  using namespace stateio;
  putVector(out, pairA);
  putVector(out, pairB);
  putVector(out, pairHistory);
  putVector(out, incidentStart);
  putVector(out, incident);
  putVector(out, wallParticle);
  putVector(out, wallIndex);
  putVector(out, wallHistory);
  putVector(out, wallStart);
  put(out, skin);
  put(out, builds);
  putVector(out, positionAtBuild_);
  put(out, wallPositionAtBuild_);
}

void NeighborList::loadState(std::istream& in) {
  using namespace stateio;
  getVector(in, pairA);
  getVector(in, pairB);
  getVector(in, pairHistory);
  getVector(in, incidentStart);
  getVector(in, incident);
  getVector(in, wallParticle);
  getVector(in, wallIndex);
  getVector(in, wallHistory);
  getVector(in, wallStart);
  get(in, skin);
  get(in, builds);
  getVector(in, positionAtBuild_);
  get(in, wallPositionAtBuild_);
}

bool NeighborList::wallsMoved(const WallBox& box) const {
  for (int k = 0; k < 6; ++k)
    if (std::abs(box.walls[k].position - wallPositionAtBuild_[k]) > halfSkin()) return true;
  return false;
}

void NeighborList::build(const Particles& particles, const WallBox& box) {
  const std::size_t n = particles.size();
  const auto& x = particles.position;
  const auto& r = particles.radius;

  // Cell list over the particles' bounding box; cell side >= largest interaction distance.
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  double rMax = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    lo = lo.cwiseMin(x[i]);
    hi = hi.cwiseMax(x[i]);
    rMax = std::max(rMax, r[i]);
  }
  const double cellSide = 2.0 * rMax + skin;
  std::array<int, 3> dims{};
  for (int a = 0; a < 3; ++a)
    dims[a] = std::clamp(static_cast<int>((hi[a] - lo[a]) / cellSide), 1, 1 << 10);
  const std::size_t nCells = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  auto cellCoord = [&](const Vec3& p, int a) {
    const int c = static_cast<int>((p[a] - lo[a]) / cellSide);
    return std::clamp(c, 0, dims[a] - 1);
  };
  std::vector<std::uint32_t> cellOf(n), cellStart(nCells + 1, 0), cellItems(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t c =
        (static_cast<std::size_t>(cellCoord(x[i], 2)) * dims[1] + cellCoord(x[i], 1)) * dims[0] +
        cellCoord(x[i], 0);
    cellOf[i] = static_cast<std::uint32_t>(c);
    ++cellStart[c + 1];
  }
  for (std::size_t c = 0; c < nCells; ++c) cellStart[c + 1] += cellStart[c];
  {
    std::vector<std::uint32_t> fill(cellStart.begin(), cellStart.end() - 1);
    for (std::size_t i = 0; i < n; ++i) cellItems[fill[cellOf[i]]++] = static_cast<std::uint32_t>(i);
  }

  // Pairs: each thread scans a contiguous range of a, lists its partners b > a in sorted order;
  // ranges are concatenated in thread order, so the result equals the serial one.
  std::vector<std::uint64_t> newKeys;
  const int nThreads = omp_get_max_threads();
  std::vector<std::vector<std::uint64_t>> perThread(nThreads);
#pragma omp parallel num_threads(nThreads)
  {
    const int t = omp_get_thread_num();
    const int nt = omp_get_num_threads();
    const std::size_t begin = n * t / nt, end = n * (t + 1) / nt;
    auto& out = perThread[t];
    std::vector<std::uint32_t> partners;
    for (std::size_t a = begin; a < end; ++a) {
      partners.clear();
      const int cx = cellCoord(x[a], 0), cy = cellCoord(x[a], 1), cz = cellCoord(x[a], 2);
      for (int dz = -1; dz <= 1; ++dz) {
        const int z = cz + dz;
        if (z < 0 || z >= dims[2]) continue;
        for (int dy = -1; dy <= 1; ++dy) {
          const int y = cy + dy;
          if (y < 0 || y >= dims[1]) continue;
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = cx + dx;
            if (xx < 0 || xx >= dims[0]) continue;
            const std::size_t c = (static_cast<std::size_t>(z) * dims[1] + y) * dims[0] + xx;
            for (std::uint32_t s = cellStart[c]; s < cellStart[c + 1]; ++s) {
              const std::uint32_t b = cellItems[s];
              if (b <= a) continue;
              const double reach = r[a] + r[b] + skin;
              if ((x[b] - x[a]).squaredNorm() < reach * reach) partners.push_back(b);
            }
          }
        }
      }
      std::sort(partners.begin(), partners.end());
      for (std::uint32_t b : partners) out.push_back(pairKey(static_cast<std::uint32_t>(a), b));
    }
  }
  std::size_t total = 0;
  for (auto& v : perThread) total += v.size();
  newKeys.reserve(total);
  for (auto& v : perThread) newKeys.insert(newKeys.end(), v.begin(), v.end());

  std::vector<std::uint64_t> oldKeys(pairA.size());
  for (std::size_t p = 0; p < pairA.size(); ++p) oldKeys[p] = pairKey(pairA[p], pairB[p]);
  std::vector<contact::ContactHistory> hist;
  mergeHistory(oldKeys, pairHistory, newKeys, hist);
  pairHistory.swap(hist);
  pairA.resize(newKeys.size());
  pairB.resize(newKeys.size());
  for (std::size_t p = 0; p < newKeys.size(); ++p) {
    pairA[p] = static_cast<std::uint32_t>(newKeys[p] >> 32);
    pairB[p] = static_cast<std::uint32_t>(newKeys[p] & 0xffffffffu);
  }

  incidentStart.assign(n + 1, 0);
  for (std::size_t p = 0; p < pairA.size(); ++p) {
    ++incidentStart[pairA[p] + 1];
    ++incidentStart[pairB[p] + 1];
  }
  for (std::size_t i = 0; i < n; ++i) incidentStart[i + 1] += incidentStart[i];
  incident.resize(incidentStart[n]);
  {
    std::vector<std::uint32_t> fill(incidentStart.begin(), incidentStart.end() - 1);
    for (std::size_t p = 0; p < pairA.size(); ++p) {
      incident[fill[pairA[p]]++] = static_cast<std::uint32_t>(2 * p);
      incident[fill[pairB[p]]++] = static_cast<std::uint32_t>(2 * p + 1);
    }
  }

  // Wall candidates.
  std::vector<std::uint64_t> oldWallKeys(wallParticle.size()), newWallKeys;
  for (std::size_t w = 0; w < wallParticle.size(); ++w)
    oldWallKeys[w] = pairKey(wallParticle[w], wallIndex[w]);
  wallStart.assign(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 6; ++k) {
      const Wall& w = box.walls[k];
      const double gap = w.distance(x[i]);
      if (gap < r[i] + skin) newWallKeys.push_back(pairKey(static_cast<std::uint32_t>(i), k));
    }
    wallStart[i + 1] = static_cast<std::uint32_t>(newWallKeys.size());
  }
  std::vector<contact::ContactHistory> wallHist;
  mergeHistory(oldWallKeys, wallHistory, newWallKeys, wallHist);
  wallHistory.swap(wallHist);
  wallParticle.resize(newWallKeys.size());
  wallIndex.resize(newWallKeys.size());
  for (std::size_t w = 0; w < newWallKeys.size(); ++w) {
    wallParticle[w] = static_cast<std::uint32_t>(newWallKeys[w] >> 32);
    wallIndex[w] = static_cast<std::uint8_t>(newWallKeys[w] & 0xffu);
  }

  positionAtBuild_ = x;
  for (int k = 0; k < 6; ++k) wallPositionAtBuild_[k] = box.walls[k].position;
  ++builds;
}

}  // namespace grainlab

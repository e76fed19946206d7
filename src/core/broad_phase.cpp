#include "core/broad_phase.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "core/state_io.hpp"

namespace grainlab {

void BroadPhase::saveState(std::ostream& out) const {
  using namespace stateio;
  put(out, skin);
  put(out, builds);
  putVector(out, positionAtBuild_);
  put(out, wallPositionAtBuild_);
  put(out, cellAtBuildInverse_);
}

void BroadPhase::loadState(std::istream& in) {
  using namespace stateio;
  get(in, skin);
  get(in, builds);
  getVector(in, positionAtBuild_);
  get(in, wallPositionAtBuild_);
  get(in, cellAtBuildInverse_);
}

bool BroadPhase::wallsMoved(const WallBox& box) const {
  for (int k = 0; k < 6; ++k)
    if (std::abs(box.walls[k].position - wallPositionAtBuild_[k]) > halfSkin()) return true;
  return false;
}

double BroadPhase::reach(const Particles& particles) const {
  double rMax = 0.0;
  for (double r : particles.radius) rMax = std::max(rMax, r);
  return 2.0 * rMax + skin;
}

void BroadPhase::assignPairs(const Particles& particles, const std::vector<PairKey>& keys, ContactStore& contacts) {
  // Candidate pairs by the shapes of their bodies. A sphere–ellipsoid pair is keyed sphere first,
  // with the image shift of the ellipsoid (negated when the two trade places), and re-sorted.
  const std::size_t n = particles.size();
  if (!particles.anyEllipsoid()) {
    contacts.sphereSphere.assign(keys, n);
    contacts.ellipsoidEllipsoid.assign({}, n);
    contacts.sphereEllipsoid.assign({}, n);
    return;
  }
  std::vector<PairKey> ss, ee, se;
  for (const PairKey& k : keys) {
    const bool sa = particles.shape[k.a] == Shape::Sphere, sb = particles.shape[k.b] == Shape::Sphere;
    if (sa && sb) ss.push_back(k);
    else if (!sa && !sb) ee.push_back(k);
    else if (sa) se.push_back(k);
    else {
      const auto s = ImageShift::unpack(k.shift);
      se.push_back({k.b, k.a, ImageShift::pack(-s[0], -s[1], -s[2])});
    }
  }
  std::sort(se.begin(), se.end());
  contacts.sphereSphere.assign(ss, n);
  contacts.ellipsoidEllipsoid.assign(ee, n);
  contacts.sphereEllipsoid.assign(se, n);
}

void BroadPhase::buildWalls(const Particles& particles, const WallBox& box, ContactStore& contacts) {
  prepareWalls(particles, box, 1);
  scanPart(particles, PeriodicCell{}, 0);
  finish(particles, box, PeriodicCell{}, contacts);
}

void BroadPhase::buildPeriodic(const Particles& particles, const PeriodicCell& cell, ContactStore& contacts) {
  preparePeriodic(particles, cell, 1);
  scanPart(particles, cell, 0);
  finish(particles, WallBox{}, cell, contacts);
}

void BroadPhase::prepareWalls(const Particles& particles, const WallBox& box, int parts) {
  (void)box;
  const std::size_t n = particles.size();
  const auto& x = particles.position;
  const auto& r = particles.radius;
  // Grid over the particles' bounding box; cell side >= largest interaction distance.
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  double rMax = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    lo = lo.cwiseMin(x[i]);
    hi = hi.cwiseMax(x[i]);
    rMax = std::max(rMax, r[i]);
  }
  periodicBuild_ = false;
  gridLow_ = lo;
  cellSide_ = 2.0 * rMax + skin;
  for (int a = 0; a < 3; ++a) dims_[a] = SpatialGrid::cellsAlong(hi[a] - lo[a], cellSide_);
  cellOf_.resize(n);
  grid_.reset(dims_);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) cellOf_[i][a] = SpatialGrid::coordinate(x[i][a], lo[a], cellSide_, dims_[a]);
    grid_.insert(static_cast<std::uint32_t>(i), cellOf_[i]);
  }
  parts_.assign(static_cast<std::size_t>(parts), {});
}

void BroadPhase::preparePeriodic(const Particles& particles, const PeriodicCell& cell, int parts) {
  const std::size_t n = particles.size();
  const auto& x = particles.position;
  const double range = reach(particles);
  const Vec3 widths = cell.widths();
  if (widths.minCoeff() < 2.0 * range)
    throw SimulationError(fmt::format(
        "periodic cell too small: its narrowest width {:.4g} m is under twice the interaction range "
        "{:.4g} m (largest diameter plus skin), so a particle could touch two images of another; use "
        "more particles (at least ~3 largest diameters per side)", widths.minCoeff(), range));
  // Grid in scaled coordinates: n_k cells along axis k, each at least `range` wide in real space
  // (the distance between the cell's faces is widths_k / n_k), so everything within range of a
  // point is in the 3x3x3 block around its cell (docs/physics.md §8.2).
  periodicBuild_ = true;
  dims_ = SpatialGrid::dimsFor({widths[0], widths[1], widths[2]}, range, std::max<std::size_t>(27, 4 * n));
  cellOf_.resize(n);
  grid_.reset(dims_);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 s = cell.hInverse * x[i];
    for (int a = 0; a < 3; ++a) cellOf_[i][a] = SpatialGrid::coordinate(s[a] * dims_[a], 0.0, 1.0, dims_[a]);
    grid_.insert(static_cast<std::uint32_t>(i), cellOf_[i]);
  }
  parts_.assign(static_cast<std::size_t>(parts), {});
}

void BroadPhase::scanPart(const Particles& particles, const PeriodicCell& cell, int part) {
  // Part `part` of parts_.size(): a contiguous range of a, each a's partners (b > a) sorted.
  const std::size_t n = particles.size(), parts = parts_.size(), t = static_cast<std::size_t>(part);
  const std::size_t begin = n * t / parts, end = n * (t + 1) / parts;
  const auto& x = particles.position;
  const auto& r = particles.radius;
  std::vector<PairKey>& out = parts_[t];
  out.clear();
  std::vector<PairKey> found;
  for (std::size_t i = begin; i < end; ++i) {
    const auto a = static_cast<std::uint32_t>(i);
    found.clear();
    if (periodicBuild_) {
      grid_.forEachAroundPeriodic(cellOf_[a], [&](std::uint32_t b, const SpatialGrid::Cell& s) {
        if (b <= a) return;
        const Vec3 image = x[b] + cell.h * Vec3(s[0], s[1], s[2]);
        const double reachAB = r[a] + r[b] + skin;
        if ((image - x[a]).squaredNorm() < reachAB * reachAB) found.push_back({a, b, ImageShift::pack(s[0], s[1], s[2])});
      });
    } else {
      grid_.forEachAround(cellOf_[a], [&](std::uint32_t b) {
        if (b <= a) return;
        const double reach = r[a] + r[b] + skin;
        if ((x[b] - x[a]).squaredNorm() < reach * reach) found.push_back({a, b, ImageShift::kZero});
      });
    }
    std::sort(found.begin(), found.end());
    out.insert(out.end(), found.begin(), found.end());
  }
}

void BroadPhase::finish(const Particles& particles, const WallBox& box, const PeriodicCell& cell,
                        ContactStore& contacts) {
  const std::size_t n = particles.size();
  const auto& x = particles.position;
  const auto& r = particles.radius;
  std::vector<PairKey> keys;
  std::size_t total = 0;
  for (const auto& v : parts_) total += v.size();
  keys.reserve(total);
  for (const auto& v : parts_) keys.insert(keys.end(), v.begin(), v.end());
  assignPairs(particles, keys, contacts);
  if (periodicBuild_) {
    contacts.sphereWall.assign({}, n);
    contacts.ellipsoidWall.assign({}, n);
    cellAtBuildInverse_ = cell.hInverse;
  } else {
    // Wall candidates, sorted by particle then wall, by shape.
    std::vector<PairKey> wallKeys, ellipsoidWallKeys;
    for (std::size_t i = 0; i < n; ++i)
      for (int k = 0; k < 6; ++k)
        if (box.walls[k].distance(x[i]) < r[i] + skin)
          (particles.shape[i] == Shape::Sphere ? wallKeys : ellipsoidWallKeys)
              .push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(k), ImageShift::kZero});
    contacts.sphereWall.assign(wallKeys, n);
    contacts.ellipsoidWall.assign(ellipsoidWallKeys, n);
    for (int k = 0; k < 6; ++k) wallPositionAtBuild_[k] = box.walls[k].position;
  }
  positionAtBuild_ = x;
  ++builds;
}

}  // namespace grainlab

#include "lab/placement.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>

#include "core/spatial_grid.hpp"

namespace grainlab::lab {

namespace {

bool tryPlace(const std::vector<double>& radii, double boxSide, bool periodic, Rng& rng, std::vector<Vec3>& pos) {
  const double rMax = radii.front();
  const double cellSide = 2.0 * rMax;
  const int dim = SpatialGrid::cellsAlong(boxSide, cellSide);
  // In a cell, the grid's cells tile the period exactly, so that the wrapped block finds images.
  const double side = periodic ? boxSide / dim : cellSide;
  SpatialGrid grid;
  grid.reset({dim, dim, dim});
  pos.assign(radii.size(), Vec3::Zero());
  for (std::size_t i = 0; i < radii.size(); ++i) {
    const double r = radii[i];
    bool placed = false;
    for (int attempt = 0; attempt < 2000 && !placed; ++attempt) {
      const double lo = periodic ? 0.0 : r, hi = periodic ? boxSide : boxSide - r;
      const Vec3 x(rng.uniform(lo, hi), rng.uniform(lo, hi), rng.uniform(lo, hi));
      SpatialGrid::Cell c{};
      for (int a = 0; a < 3; ++a) c[a] = SpatialGrid::coordinate(x[a], 0.0, side, dim);
      bool free = true;
      auto check = [&](std::uint32_t j, const Vec3& image) {
        const double reach = r + radii[j];
        if ((image - x).squaredNorm() < reach * reach) free = false;
      };
      if (periodic)
        grid.forEachAroundPeriodic(c, [&](std::uint32_t j, const SpatialGrid::Cell& s) {
          if (free) check(j, pos[j] + boxSide * Vec3(s[0], s[1], s[2]));
        });
      else
        grid.forEachAround(c, [&](std::uint32_t j) {
          if (free) check(j, pos[j]);
        });
      if (free) {
        pos[i] = x;
        grid.insert(static_cast<std::uint32_t>(i), c);
        placed = true;
      }
    }
    if (!placed) return false;
  }
  return true;
}

}  // namespace

void placeLoose(std::vector<double> diameters, double density, double voidRatio, Rng& rng, Simulation& sim) {
  const bool periodic = sim.boundary == Boundary::Periodic;
  std::sort(diameters.begin(), diameters.end(), std::greater<>());
  std::vector<double> radii(diameters.size());
  double solid = 0.0;
  for (std::size_t i = 0; i < diameters.size(); ++i) {
    radii[i] = 0.5 * diameters[i];
    solid += kPi / 6.0 * diameters[i] * diameters[i] * diameters[i];
  }
  double side = std::cbrt(solid * (1.0 + voidRatio));
  side = std::max(side, 2.0 * diameters.front());
  std::vector<Vec3> pos;
  while (!tryPlace(radii, side, periodic, rng, pos)) side *= 1.05;

  // Renumber in cell order (z, y, x) of cells about one large diameter wide.
  const int dim = SpatialGrid::cellsAlong(side, diameters.front());
  SpatialGrid grid;
  grid.reset({dim, dim, dim});
  std::vector<std::size_t> order(radii.size());
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](std::size_t i) {
    SpatialGrid::Cell c{};
    for (int a = 0; a < 3; ++a) c[a] = SpatialGrid::coordinate(pos[i][a], 0.0, diameters.front(), dim);
    return grid.cellIndex(c);
  };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
  sim.particles = Particles{};
  for (std::size_t i : order) sim.particles.addSphere(pos[i], radii[i], density);
  if (periodic) sim.cell.setBox(Vec3::Constant(side));
  else sim.box.setBounds(Vec3::Zero(), Vec3::Constant(side));
}

void placeLattice(int n, double d, double density, Simulation& sim) {
  sim.particles = Particles{};
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) sim.particles.addSphere(Vec3(i + 0.5, j + 0.5, k + 0.5) * d, 0.5 * d, density);
  if (sim.boundary == Boundary::Periodic) sim.cell.setBox(Vec3::Constant(n * d));
  else sim.box.setBounds(Vec3::Zero(), Vec3::Constant(n * d));
}

}  // namespace grainlab::lab

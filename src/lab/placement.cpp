#include "lab/placement.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>

namespace grainlab::lab {

namespace {

struct Grid {
  double side;
  int dim;
  std::vector<std::vector<std::uint32_t>> cells;
  Grid(double boxSide, double cellSide)
      : side(cellSide), dim(std::max(1, static_cast<int>(boxSide / cellSide))),
        cells(static_cast<std::size_t>(dim) * dim * dim) {}
  int coord(double v) const { return std::clamp(static_cast<int>(v / side), 0, dim - 1); }
  std::size_t index(int x, int y, int z) const { return (static_cast<std::size_t>(z) * dim + y) * dim + x; }
};

bool tryPlace(const std::vector<double>& radii, double boxSide, Rng& rng, std::vector<Vec3>& pos) {
  const double rMax = radii.front();
  Grid grid(boxSide, 2.0 * rMax);
  pos.assign(radii.size(), Vec3::Zero());
  for (std::size_t i = 0; i < radii.size(); ++i) {
    const double r = radii[i];
    bool placed = false;
    for (int attempt = 0; attempt < 2000 && !placed; ++attempt) {
      const Vec3 x(rng.uniform(r, boxSide - r), rng.uniform(r, boxSide - r), rng.uniform(r, boxSide - r));
      const int cx = grid.coord(x[0]), cy = grid.coord(x[1]), cz = grid.coord(x[2]);
      bool free = true;
      for (int dz = -1; dz <= 1 && free; ++dz)
        for (int dy = -1; dy <= 1 && free; ++dy)
          for (int dx = -1; dx <= 1 && free; ++dx) {
            const int X = cx + dx, Y = cy + dy, Z = cz + dz;
            if (X < 0 || Y < 0 || Z < 0 || X >= grid.dim || Y >= grid.dim || Z >= grid.dim) continue;
            for (std::uint32_t j : grid.cells[grid.index(X, Y, Z)]) {
              const double reach = r + radii[j];
              if ((pos[j] - x).squaredNorm() < reach * reach) {
                free = false;
                break;
              }
            }
          }
      if (free) {
        pos[i] = x;
        grid.cells[grid.index(cx, cy, cz)].push_back(static_cast<std::uint32_t>(i));
        placed = true;
      }
    }
    if (!placed) return false;
  }
  return true;
}

}  // namespace

void placeLoose(std::vector<double> diameters, double density, double voidRatio, Rng& rng,
                Particles& particles, WallBox& box) {
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
  while (!tryPlace(radii, side, rng, pos)) side *= 1.05;

  // Renumber in cell order (z, y, x) of cells about one large diameter wide.
  Grid grid(side, diameters.front());
  std::vector<std::size_t> order(radii.size());
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](std::size_t i) {
    return grid.index(grid.coord(pos[i][0]), grid.coord(pos[i][1]), grid.coord(pos[i][2]));
  };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
  particles = Particles{};
  for (std::size_t i : order) particles.addSphere(pos[i], radii[i], density);
  box.setBounds(Vec3::Zero(), Vec3::Constant(side));
}

}  // namespace grainlab::lab

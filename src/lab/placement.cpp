#include "lab/placement.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numeric>

#include "core/spatial_grid.hpp"

namespace grainlab::lab {

namespace {

// Random sequential placement in the box [0, extent] (a periodic cell: the cube of side extent[0]).
// With cylinder > 0, only in the cylinder of that radius about the box's vertical centre line (a
// draw outside it counts as a failed attempt).
bool tryPlace(const std::vector<double>& radii, const Vec3& extent, bool periodic, Rng& rng, std::vector<Vec3>& pos,
              double cylinder = 0.0) {
  const double rMax = radii.front();
  const double cellSide = 2.0 * rMax;
  const double boxSide = extent[0];  // the period of a cell
  std::array<int, 3> dim{};
  for (int a = 0; a < 3; ++a) dim[a] = SpatialGrid::cellsAlong(extent[a], cellSide);
  // In a cell, the grid's cells tile the period exactly, so that the wrapped block finds images.
  const double side = periodic ? boxSide / dim[0] : cellSide;
  SpatialGrid grid;
  grid.reset({dim[0], dim[1], dim[2]});
  pos.assign(radii.size(), Vec3::Zero());
  for (std::size_t i = 0; i < radii.size(); ++i) {
    const double r = radii[i];
    bool placed = false;
    for (int attempt = 0; attempt < 2000 && !placed; ++attempt) {
      // Drawn z first, then y, then x: the order in which g++ evaluated the three draws of the
      // earlier Vec3(u(), u(), u()), kept so that every seed places its grains where it did.
      Vec3 x;
      for (int a = 2; a >= 0; --a) x[a] = rng.uniform(periodic ? 0.0 : r, periodic ? boxSide : extent[a] - r);
      if (cylinder > 0.0 && std::hypot(x[0] - 0.5 * extent[0], x[1] - 0.5 * extent[1]) > cylinder - r) continue;
      SpatialGrid::Cell c{};
      for (int a = 0; a < 3; ++a) c[a] = SpatialGrid::coordinate(x[a], 0.0, side, dim[a]);
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

// The grains of a placement, largest first (tryPlace places the large ones while there is room),
// and their solid volume.
struct Grains {
  std::vector<double> radii;
  double solid = 0.0;  // [m^3]
  double dMax = 0.0;   // [m]
};
Grains largestFirst(std::vector<double> diameters) {
  std::sort(diameters.begin(), diameters.end(), std::greater<>());
  Grains g;
  g.radii.resize(diameters.size());
  for (std::size_t i = 0; i < diameters.size(); ++i) {
    g.radii[i] = 0.5 * diameters[i];
    g.solid += kPi / 6.0 * diameters[i] * diameters[i] * diameters[i];
  }
  g.dMax = diameters.front();
  return g;
}

// Places the grains in a column of the given footprint, raising its height by 5 % until they fit;
// returns the height.
double placeInColumn(const std::vector<double>& radii, double width, double height, Rng& rng, std::vector<Vec3>& pos) {
  while (!tryPlace(radii, Vec3(width, width, height), false, rng, pos)) height *= 1.05;
  return height;
}

// Adds the spheres renumbered in cell order (z, y, x) of cells about one large diameter wide, so
// that neighbours in space are neighbours in memory.
void addInCellOrder(const std::vector<Vec3>& pos, const std::vector<double>& radii, const Vec3& extent, double density,
                    Simulation& sim, bool append = false) {
  const double dMax = 2.0 * radii.front();
  std::array<int, 3> dim{};
  for (int a = 0; a < 3; ++a) dim[a] = SpatialGrid::cellsAlong(extent[a], dMax);
  SpatialGrid grid;
  grid.reset({dim[0], dim[1], dim[2]});
  std::vector<std::size_t> order(radii.size());
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](std::size_t i) {
    SpatialGrid::Cell c{};
    for (int a = 0; a < 3; ++a) c[a] = SpatialGrid::coordinate(pos[i][a], 0.0, dMax, dim[a]);
    return grid.cellIndex(c);
  };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
  if (!append) sim.particles = Particles{};
  for (std::size_t i : order) sim.particles.addSphere(pos[i], radii[i], density);
}

}  // namespace

void placeLoose(std::vector<double> diameters, double density, double voidRatio, Rng& rng, Simulation& sim) {
  const bool periodic = sim.boundary == Boundary::Periodic;
  const Grains g = largestFirst(std::move(diameters));
  const std::vector<double>& radii = g.radii;
  const double solid = g.solid;
  double side = std::cbrt(solid * (1.0 + voidRatio));
  side = std::max(side, 2.0 * g.dMax);
  std::vector<Vec3> pos;
  while (!tryPlace(radii, Vec3::Constant(side), periodic, rng, pos)) side *= 1.05;

  addInCellOrder(pos, radii, Vec3::Constant(side), density, sim);
  if (periodic) sim.cell.setBox(Vec3::Constant(side));
  else sim.box.setBounds(Vec3::Zero(), Vec3::Constant(side));
}

CylinderPlacement placeCylinder(std::vector<double> diameters, double density, double voidRatio, double aspect,
                                double binSide, double shrink, Rng& rng, Simulation& sim) {
  const Grains g = largestFirst(std::move(diameters));
  // pi R^2 (2 R aspect) = solid (1 + e)
  double radius = std::max(std::cbrt(g.solid * (1.0 + voidRatio) / (2.0 * kPi * aspect)), 2.0 * g.dMax);
  std::vector<Vec3> pos;
  while (!tryPlace(g.radii, Vec3(2.0 * radius, 2.0 * radius, 2.0 * aspect * radius), false, rng, pos, radius))
    radius *= 1.05;
  const double height = 2.0 * aspect * radius;
  addInCellOrder(pos, g.radii, Vec3(2.0 * radius, 2.0 * radius, height), density, sim);
  // The lateral walls stand three radii off the axis: never touched (a grain past them has left the
  // sample, an error), and the broad phase's grid spans the grains only.
  sim.box.setBounds(Vec3(-2.0 * radius, -2.0 * radius, 0.0), Vec3(4.0 * radius, 4.0 * radius, height));
  Membrane& m = sim.membrane;
  m = Membrane{};
  m.axisX = m.axisY = radius;
  m.rigid = true;  // a rigid cylinder until the test begins
  m.radius = radius;
  m.around = std::max(8, static_cast<int>(std::lround(2.0 * kPi * radius * shrink / binSide)));
  m.along = std::max(4, static_cast<int>(std::lround(height * shrink / binSide)));
  // The loaded shell: half a mean grain radius deep.
  double meanRadius = 0.0;
  for (double r : g.radii) meanRadius += r;
  m.shell = 0.5 * meanRadius / static_cast<double>(g.radii.size());
  m.measure(sim.particles, 0.0, height);
  CylinderPlacement out;
  out.radius = radius;
  out.height = height;
  return out;
}

ColumnPlacement placeColumn(std::vector<double> diameters, double density, double voidRatio, double bedVoidRatio,
                            double dropHeight, Rng& rng, Simulation& sim) {
  const Grains g = largestFirst(std::move(diameters));
  const std::vector<double>& radii = g.radii;
  const double solid = g.solid;
  // A square footprint on which the settled bed (at about bedVoidRatio) is roughly a cube.
  const double width = std::max(std::cbrt(solid * (1.0 + bedVoidRatio)), 2.0 * g.dMax);
  std::vector<Vec3> pos;
  const double height = placeInColumn(radii, width, std::max(solid * (1.0 + voidRatio) / (width * width), 2.0 * g.dMax),
                                      rng, pos);
  for (Vec3& x : pos) x.z() += dropHeight;
  addInCellOrder(pos, radii, Vec3(width, width, height + dropHeight), density, sim);
  sim.box.setBounds(Vec3::Zero(), Vec3(width, width, height + dropHeight));
  ColumnPlacement out;
  out.width = width;
  out.cloudHeight = height;
  out.cloudSolidFraction = solid / (width * width * height);
  return out;
}

double appendSlab(std::vector<double> diameters, double density, double voidRatio, double width, double zBottom, Rng& rng,
                  Simulation& sim) {
  const Grains g = largestFirst(std::move(diameters));
  const std::vector<double>& radii = g.radii;
  const double solid = g.solid;
  std::vector<Vec3> pos;
  const double height = placeInColumn(radii, width, std::max(solid * (1.0 + voidRatio) / (width * width), 2.0 * g.dMax),
                                      rng, pos);
  // Cell order within the slab (its own z from the slab's bottom), then lifted onto the bed.
  addInCellOrder(pos, radii, Vec3(width, width, height), density, sim, true);
  for (std::size_t i = sim.particles.size() - pos.size(); i < sim.particles.size(); ++i) sim.particles.position[i].z() += zBottom;
  return height;
}

double solidVolumeBetween(const Particles& particles, double z0, double z1) {
  // The volume of a sphere of radius r below the plane at height t above its lowest point
  // (0 <= t <= 2r) is the cap pi t^2 (3r - t) / 3.
  auto below = [](double r, double t) {
    t = std::clamp(t, 0.0, 2.0 * r);
    return kPi * t * t * (3.0 * r - t) / 3.0;
  };
  double v = 0.0;
  for (std::size_t i = 0; i < particles.size(); ++i) {
    const double r = particles.radius[i];
    const double bottom = particles.position[i].z() - r;
    v += below(r, z1 - bottom) - below(r, z0 - bottom);
  }
  return v;
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

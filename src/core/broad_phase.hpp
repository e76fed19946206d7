#pragma once
// Broad phase: a Verlet list with a skin, built from the spatial grid (O(N)). A pair is listed when
// its bodies' bounding spheres come within the skin of each other; the lists stay valid while no
// particle (or wall) has moved more than skin/2 relative to where it was at the last build — in a
// periodic cell relative to where the homogeneous deformation since then has carried it, and while
// that deformation itself has not closed gaps by more than the skin.
#include <array>
#include <cstdint>
#include <iosfwd>
#include <vector>

#include "core/contact_list.hpp"
#include "core/particles.hpp"
#include "core/periodic_cell.hpp"
#include "core/spatial_grid.hpp"
#include "core/walls.hpp"

namespace grainlab {

class BroadPhase {
 public:
  double skin = 0.0;  // [m]
  long builds = 0;

  // Rebuilds every kind's list for the current positions in a box of walls, carrying history.
  void buildWalls(const Particles& particles, const WallBox& box, ContactStore& contacts);
  // The same in a periodic cell; particles must lie in the cell (scaled coordinates in [0, 1)).
  // Throws SimulationError when the cell is narrower than two interaction ranges.
  void buildPeriodic(const Particles& particles, const PeriodicCell& cell, ContactStore& contacts);

  // The same rebuild in three phases, so that the candidate scan runs on the step's threads
  // (Simulation::updateBroadPhase): prepare (one thread: bins the particles into the grid; the
  // periodic one throws as buildPeriodic does), scanPart(part, parts) for every part (any thread,
  // each part once: the candidates of a contiguous range of particles), finish (one thread: joins
  // the parts in order and assigns the lists, carrying history). The parts' ranges are contiguous
  // and each is sorted, so the lists do not depend on the number of parts.
  void prepareWalls(const Particles& particles, const WallBox& box, int parts);
  void preparePeriodic(const Particles& particles, const PeriodicCell& cell, int parts);
  void scanPart(const Particles& particles, const PeriodicCell& cell, int part);
  void finish(const Particles& particles, const WallBox& box, const PeriodicCell& cell, ContactStore& contacts);

  double halfSkin() const { return 0.5 * skin; }
  // Whether a wall moved more than skin/2 since the last build.
  bool wallsMoved(const WallBox& box) const;
  // Largest distance at which two bodies can interact: twice the largest bounding radius plus skin.
  double reach(const Particles& particles) const;
  // Narrowest a periodic cell may be for these particles: no body may touch two images of another.
  double minimumCellWidth(const Particles& particles) const { return 2.0 * reach(particles); }
  // Deformation of the cell since the last build, F = H H_build^-1.
  Mat3 cellDeformation(const PeriodicCell& cell) const { return cell.h * cellAtBuildInverse_; }

  const std::vector<Vec3>& positionsAtBuild() const { return positionAtBuild_; }

  void saveState(std::ostream& out) const;
  void loadState(std::istream& in);

 private:
  std::vector<Vec3> positionAtBuild_;
  std::array<double, 6> wallPositionAtBuild_{};
  Mat3 cellAtBuildInverse_ = Mat3::Identity();
  SpatialGrid grid_;
  // The build under way: its boundary, its grid's geometry and the candidates found per part.
  bool periodicBuild_ = false;
  Vec3 gridLow_ = Vec3::Zero();
  double cellSide_ = 0.0;
  SpatialGrid::Cell dims_{};
  std::vector<SpatialGrid::Cell> cellOf_;
  std::vector<std::vector<PairKey>> parts_;
  // Distributes candidate pairs (sorted, a < b) to the pair kinds by shape.
  static void assignPairs(const Particles& particles, const std::vector<PairKey>& keys, ContactStore& contacts);
};

}  // namespace grainlab

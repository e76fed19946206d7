#pragma once
// The engine's one spatial grid: a regular block of cells, each a list of items in insertion order
// (a linked cell list: head/tail per cell, next per item). The broad phase (wall box and periodic
// cell), the loose placement of a sample and the neighbourhoods of the grain kinematics all use it.
// Cells are chosen at least as wide as the distance searched, so every item within that distance of
// a point lies in the 3x3x3 block of cells around the point's cell.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace grainlab {

class SpatialGrid {
 public:
  using Cell = std::array<int, 3>;
  static constexpr int kMaxDim = 1 << 10;

  // Number of cells of at least `side` along an extent: floor(extent / side), in [1, kMaxDim].
  static int cellsAlong(double extent, double side) {
    return std::clamp(static_cast<int>(extent / side), 1, kMaxDim);
  }
  // Cells along each axis for cells of at least `side` (cellsAlong), coarsened (the largest count
  // halved, cells only grow) until there are at most maxCells: a dilute set must not cost a grid of
  // millions of empty cells.
  static Cell dimsFor(const std::array<double, 3>& extent, double side, std::size_t maxCells) {
    Cell d{cellsAlong(extent[0], side), cellsAlong(extent[1], side), cellsAlong(extent[2], side)};
    while (static_cast<std::size_t>(d[0]) * d[1] * d[2] > maxCells) {
      int& largest = *std::max_element(d.begin(), d.end());
      largest = std::max(1, largest / 2);
    }
    return d;
  }
  // Cell coordinate floor((x - origin) / side) - offset, clamped to [0, dim).
  static int coordinate(double x, double origin, double side, int dim, int offset = 0) {
    return std::clamp(static_cast<int>(std::floor((x - origin) / side)) - offset, 0, dim - 1);
  }

  // An empty grid of dims[0] x dims[1] x dims[2] cells.
  void reset(const Cell& dims) {
    dims_ = dims;
    const std::size_t n = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
    head_.assign(n, kEnd);
    tail_.assign(n, kEnd);
    next_.clear();
  }
  const Cell& dims() const { return dims_; }
  std::size_t cellIndex(const Cell& c) const {
    return (static_cast<std::size_t>(c[2]) * dims_[1] + c[1]) * dims_[0] + c[0];
  }

  // Appends `item` to cell c: a cell's items are visited in the order they were inserted.
  void insert(std::uint32_t item, const Cell& c) {
    if (item >= next_.size()) next_.resize(static_cast<std::size_t>(item) + 1, kEnd);
    next_[item] = kEnd;
    const std::size_t k = cellIndex(c);
    if (tail_[k] == kEnd) head_[k] = item;
    else next_[tail_[k]] = item;
    tail_[k] = item;
  }

  // f(item) for every item of the cells of the 3x3x3 block around c that lie inside the grid, cells
  // in z, y, x order.
  template <class F>
  void forEachAround(const Cell& c, F&& f) const {
    for (int dz = -1; dz <= 1; ++dz) {
      const int z = c[2] + dz;
      if (z < 0 || z >= dims_[2]) continue;
      for (int dy = -1; dy <= 1; ++dy) {
        const int y = c[1] + dy;
        if (y < 0 || y >= dims_[1]) continue;
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = c[0] + dx;
          if (x < 0 || x >= dims_[0]) continue;
          for (std::uint32_t i = head_[cellIndex({x, y, z})]; i != kEnd; i = next_[i]) f(i);
        }
      }
    }
  }

  // The same in a periodic grid: the block wraps around, and f(item, shift) receives the image
  // shift (in periods along each axis) of the wrapped cell. Every (cell, shift) of the block is
  // distinct even for grids of one or two cells along an axis, so no item image is visited twice.
  template <class F>
  void forEachAroundPeriodic(const Cell& c, F&& f) const {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          Cell cell{}, shift{};
          const int d[3] = {dx, dy, dz};
          for (int a = 0; a < 3; ++a) {
            const int u = c[a] + d[a];
            shift[a] = u < 0 ? -1 : (u >= dims_[a] ? 1 : 0);
            cell[a] = u - shift[a] * dims_[a];
          }
          for (std::uint32_t i = head_[cellIndex(cell)]; i != kEnd; i = next_[i]) f(i, shift);
        }
  }

 private:
  static constexpr std::uint32_t kEnd = ~std::uint32_t{0};
  Cell dims_{};
  std::vector<std::uint32_t> head_, tail_, next_;
};

}  // namespace grainlab

#pragma once
// Broad phase: a Verlet list with a skin, built from a cell list (O(N)), and the persistent contact
// history that lives beside it. A pair (a < b) is listed when |xb - xa| < ra + rb + skin; the list
// stays valid while no particle (or wall) has moved more than skin/2 since it was built. Pairs are
// kept sorted by (a, b) so that history is carried over by a linear merge, and a particle's incident
// pairs are listed in a fixed order (CSR) so force sums do not depend on the thread count.
#include <array>
#include <cstdint>
#include <iosfwd>
#include <vector>

#include "contact/models.hpp"
#include "core/particles.hpp"
#include "core/walls.hpp"

namespace grainlab {

class NeighborList {
 public:
  // Candidate particle pairs (a < b) and their contact history, parallel arrays.
  std::vector<std::uint32_t> pairA, pairB;
  std::vector<contact::ContactHistory> pairHistory;
  // CSR of incident pairs per particle: entry = 2 * pairIndex + (particle is B ? 1 : 0).
  std::vector<std::uint32_t> incidentStart, incident;
  // Candidate particle-wall contacts, sorted by particle then wall, with history; CSR by particle.
  std::vector<std::uint32_t> wallParticle;
  std::vector<std::uint8_t> wallIndex;
  std::vector<contact::ContactHistory> wallHistory;
  std::vector<std::uint32_t> wallStart;

  double skin = 0.0;       // [m]
  long builds = 0;

  // Rebuilds the lists for the current positions, carrying history of pairs still listed.
  void build(const Particles& particles, const WallBox& box);
  // Largest displacement allowed to any particle or wall before a rebuild is due.
  double halfSkin() const { return 0.5 * skin; }
  // Whether a wall moved more than skin/2 since the last build.
  bool wallsMoved(const WallBox& box) const;

  const std::vector<Vec3>& positionsAtBuild() const { return positionAtBuild_; }

  // Exact binary state for checkpoints (state_io.hpp).
  void saveState(std::ostream& out) const;
  void loadState(std::istream& in);

 private:
  std::vector<Vec3> positionAtBuild_;
  std::array<double, 6> wallPositionAtBuild_{};
};

}  // namespace grainlab

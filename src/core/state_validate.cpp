// Simulation::validateState: a loaded state (a checkpoint) is checked before the engine steps it,
// so that an inconsistent file is an error message and never an out-of-range index, a huge
// allocation or a NaN in the contact search. A first version (sizes, indices, finite numbers);
// the engine's owner extends it with the invariants of new state.
#include <fmt/format.h>

#include <cmath>

#include "core/errors.hpp"
#include "core/simulation.hpp"

namespace grainlab {

namespace {

[[noreturn]] void invalid(const std::string& what) { throw InputError("inconsistent state: " + what); }

template <class V>
void sameSize(const V& v, std::size_t n, const char* name, const char* of) {
  if (v.size() != n) invalid(fmt::format("{} has {} entries for {} {}", name, v.size(), n, of));
}

bool finite(const Vec3& v) { return v.allFinite(); }

// A CSR start array: n + 1 entries, non-decreasing from 0 to `total`.
template <class V>
void checkStarts(const V& start, std::size_t n, std::size_t total, const char* name) {
  sameSize(start, n + 1, name, "particles + 1");
  if (start.front() != 0 || start.back() != total) invalid(fmt::format("{} does not run from 0 to {}", name, total));
  for (std::size_t i = 0; i < n; ++i)
    if (start[i + 1] < start[i]) invalid(fmt::format("{} decreases at particle {}", name, i));
}

}  // namespace

void Simulation::validateState() const {
  const Particles& p = particles;
  const std::size_t n = p.size();
  if (n < 2) invalid(fmt::format("{} particles", n));
  for (const auto* v : {&p.velocity, &p.angularVelocity, &p.force, &p.torque, &p.referencePosition})
    sameSize(*v, n, "a per-particle vector", "particles");
  for (const auto* v : {&p.radius, &p.mass, &p.inertia, &p.invMass, &p.invInertia, &p.rollingFriction, &p.sphericity,
                        &p.rotationPath})
    sameSize(*v, n, "a per-particle value", "particles");
  sameSize(p.orientation, n, "orientation", "particles");
  sameSize(p.referenceOrientation, n, "referenceOrientation", "particles");

  for (int k = 0; k < 6; ++k) {
    const Wall& w = box.walls[k];
    if (w.axis != k / 2 || w.side != k % 2) invalid(fmt::format("wall {} has axis {} side {}", k, w.axis, w.side));
    if (!std::isfinite(w.position) || !std::isfinite(w.velocity) || !std::isfinite(w.servoIntegral))
      invalid(fmt::format("wall {} has a non-finite position or speed", k));
  }
  for (int a = 0; a < 3; ++a)
    if (!(box.length(a) > 0.0)) invalid(fmt::format("box length {} along axis {}", box.length(a), a));

  double rMin = INFINITY, rMax = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(p.radius[i] > 0.0) || !std::isfinite(p.radius[i]) || !(p.mass[i] > 0.0) || !std::isfinite(p.mass[i]) ||
        !(p.inertia[i] > 0.0) || !std::isfinite(p.inertia[i]))
      invalid(fmt::format("particle {} has radius {}, mass {}, inertia {}", i, p.radius[i], p.mass[i], p.inertia[i]));
    if (!finite(p.position[i]) || !finite(p.velocity[i]) || !finite(p.angularVelocity[i]) ||
        !finite(p.referencePosition[i]) || !p.orientation[i].coeffs().allFinite() || !std::isfinite(p.rotationPath[i]))
      invalid(fmt::format("particle {} has a non-finite position, velocity or orientation", i));
    for (int a = 0; a < 3; ++a)
      if (p.position[i][a] < box.lower(a).position - box.length(a) || p.position[i][a] > box.upper(a).position + box.length(a))
        invalid(fmt::format("particle {} lies far outside the walls", i));
    rMin = std::min(rMin, p.radius[i]);
    rMax = std::max(rMax, p.radius[i]);
  }
  // The cell list has cells of 2 r_max + skin: a box very much larger than its particles would ask
  // for an absurd number of cells (a legitimate sample has about 11 per particle at e = 20).
  double cells = 1.0;
  for (int a = 0; a < 3; ++a) cells *= std::max(1.0, box.length(a) / (2.0 * rMax));
  if (cells > 64.0 * static_cast<double>(n) + 1e6) invalid("the box is far too large for its particles");

  const NeighborList& nl = neighbors;
  if (!(nl.skin > 0.0) || !(nl.skin <= 2.0 * rMin)) invalid(fmt::format("neighbour skin {}", nl.skin));
  const std::size_t pairs = nl.pairA.size();
  sameSize(nl.pairB, pairs, "pairB", "pairs");
  sameSize(nl.pairHistory, pairs, "pairHistory", "pairs");
  for (std::size_t k = 0; k < pairs; ++k) {
    if (!(nl.pairA[k] < nl.pairB[k] && nl.pairB[k] < n))
      invalid(fmt::format("pair {} joins particles {} and {} of {}", k, nl.pairA[k], nl.pairB[k], n));
    if (k > 0 && !(nl.pairA[k - 1] < nl.pairA[k] || (nl.pairA[k - 1] == nl.pairA[k] && nl.pairB[k - 1] < nl.pairB[k])))
      invalid(fmt::format("pairs not sorted at {}", k));
  }
  checkStarts(nl.incidentStart, n, nl.incident.size(), "incidentStart");
  if (nl.incident.size() != 2 * pairs) invalid("incident lists do not have two entries per pair");
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t s = nl.incidentStart[i]; s < nl.incidentStart[i + 1]; ++s) {
      const std::uint32_t e = nl.incident[s];
      if (e / 2 >= pairs || (e % 2 ? nl.pairB : nl.pairA)[e / 2] != i)
        invalid(fmt::format("incident entry {} of particle {} is not one of its pairs", e, i));
    }
  const std::size_t walls = nl.wallParticle.size();
  sameSize(nl.wallIndex, walls, "wallIndex", "wall contacts");
  sameSize(nl.wallHistory, walls, "wallHistory", "wall contacts");
  checkStarts(nl.wallStart, n, walls, "wallStart");
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t c = nl.wallStart[i]; c < nl.wallStart[i + 1]; ++c)
      if (nl.wallParticle[c] != i || nl.wallIndex[c] >= 6)
        invalid(fmt::format("wall contact {} of particle {} joins particle {} and wall {}", c, i, nl.wallParticle[c],
                            nl.wallIndex[c]));
  sameSize(nl.positionsAtBuild(), n, "positionsAtBuild", "particles");
  for (const auto& h : nl.pairHistory)
    if (!finite(h.shearForce) || !finite(h.moment) || !finite(h.prevNormal)) invalid("a contact history is not finite");
  for (const auto& h : nl.wallHistory)
    if (!finite(h.shearForce) || !finite(h.moment) || !finite(h.prevNormal)) invalid("a wall contact history is not finite");

  if (!(dt > 0.0) || !std::isfinite(dt) || !std::isfinite(time) || stepCount < 0)
    invalid(fmt::format("time step {}, time {}, step {}", dt, time, stepCount));
}

}  // namespace grainlab

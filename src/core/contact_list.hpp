#pragma once
// Contact storage, one list per pair kind (sphere–sphere, sphere–wall, ...): the candidate pairs of
// the broad phase with their history and the per-contact results of the latest step, as parallel
// arrays. Pairs are sorted by (a, b, image shift), so history is carried over a rebuild by a linear
// merge of the keys, and every particle's contacts are listed in a fixed order (CSR) so that force
// sums do not depend on the thread count.
#include <algorithm>
#include <array>
#include <compare>
#include <type_traits>
#include <cstdint>
#include <iosfwd>
#include <vector>

#include "contact/models.hpp"
#include "core/periodic_cell.hpp"
#include "core/state_io.hpp"

namespace grainlab {

// Key of a candidate contact: bodies a and b (for a wall kind, b is the wall's index) and the packed
// image shift of b (ImageShift::kZero outside a periodic cell).
struct PairKey {
  std::uint32_t a = 0, b = 0, shift = ImageShift::kZero;
  auto operator<=>(const PairKey&) const = default;
};

// The pair kinds. Each names its history type, whether its second body is a wall (plane), and
// whether its pairs are keyed with a < b (the pair kinds of one shape) or by role (sphere first,
// ellipsoid second, whatever their indices).
struct SphereSphere {
  using History = contact::ContactHistory;
  static constexpr bool kPlane = false;
  static constexpr bool kIndexOrdered = true;
  static constexpr const char* kName = "sphere-sphere";
};
struct SpherePlane {
  using History = contact::ContactHistory;
  static constexpr bool kPlane = true;
  static constexpr bool kIndexOrdered = false;
  static constexpr const char* kName = "sphere-wall";
};
struct EllipsoidEllipsoid {
  using History = contact::EllipsoidHistory;
  static constexpr bool kPlane = false;
  static constexpr bool kIndexOrdered = true;
  static constexpr const char* kName = "ellipsoid-ellipsoid";
};
struct SphereEllipsoid {
  using History = contact::EllipsoidHistory;
  static constexpr bool kPlane = false;
  static constexpr bool kIndexOrdered = false;
  static constexpr const char* kName = "sphere-ellipsoid";
};
struct EllipsoidPlane {
  using History = contact::ContactHistory;
  static constexpr bool kPlane = true;
  static constexpr bool kIndexOrdered = false;
  static constexpr const char* kName = "ellipsoid-wall";
};

template <class Kind>
class ContactList {
 public:
  using KindType = Kind;
  using History = typename Kind::History;
  std::vector<std::uint32_t> a, b, shift;
  std::vector<History> history;
  // Results of the latest step. Pair kinds: force of A on B, and the total torque on A and on B.
  // Plane kinds: force of the wall on the particle (body a) and the torque on it (torqueA).
  std::vector<Vec3> force, torqueA, torqueB;
  // CSR of each particle's entries: 2 c + (1 when the particle is body b of contact c).
  std::vector<std::uint32_t> incidentStart, incident;
  // Result slots not yet written since the list changed (a rebuild or a load): the next step
  // writes every slot once, after that apart pairs keep their zero slots without a write.
  bool slotsStale = true;

  std::size_t size() const { return a.size(); }
  PairKey key(std::size_t c) const { return {a[c], b[c], shift[c]}; }

  // Replaces the list by `keys` (sorted, unique), carrying the history of every key present before.
  void assign(const std::vector<PairKey>& keys, std::size_t nParticles) {
    std::vector<History> carried(keys.size(), History{});
    std::size_t o = 0;
    for (std::size_t n = 0; n < keys.size(); ++n) {
      while (o < a.size() && key(o) < keys[n]) ++o;
      if (o < a.size() && key(o) == keys[n]) carried[n] = history[o];
    }
    history.swap(carried);
    a.resize(keys.size());
    b.resize(keys.size());
    shift.resize(keys.size());
    for (std::size_t c = 0; c < keys.size(); ++c) {
      a[c] = keys[c].a;
      b[c] = keys[c].b;
      shift[c] = keys[c].shift;
    }
    force.resize(keys.size());
    torqueA.resize(keys.size());
    if (!Kind::kPlane) torqueB.resize(keys.size());
    buildIncidence(nParticles);
    slotsStale = true;
  }

  // Re-keys the contacts after particles were moved by whole periods: particle i was shifted by
  // -H wrap[i], so the image of b seen from a moves by wrap[b] - wrap[a]. Keys are re-sorted (with
  // their history) so that the next merge finds them.
  void applyWrap(const std::vector<std::array<int, 3>>& wrap) {
    static_assert(!Kind::kPlane);
    std::vector<PairKey> keys(size());
    std::vector<std::uint32_t> order(size());
    for (std::size_t c = 0; c < size(); ++c) {
      auto s = ImageShift::unpack(shift[c]);
      for (int k = 0; k < 3; ++k) s[k] += wrap[b[c]][k] - wrap[a[c]][k];
      keys[c] = {a[c], b[c], ImageShift::pack(s[0], s[1], s[2])};
      order[c] = static_cast<std::uint32_t>(c);
    }
    std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) { return keys[x] < keys[y]; });
    std::vector<History> h(size());
    for (std::size_t c = 0; c < size(); ++c) {
      h[c] = history[order[c]];
      a[c] = keys[order[c]].a;
      b[c] = keys[order[c]].b;
      shift[c] = keys[order[c]].shift;
    }
    history.swap(h);
    slotsStale = true;
  }


  void saveState(std::ostream& out) const {
    using namespace stateio;
    putVector(out, a);
    putVector(out, b);
    putVector(out, shift);
    putVector(out, history);
    putVector(out, force);
    putVector(out, torqueA);
    putVector(out, torqueB);
  }
  void loadState(std::istream& in) {
    using namespace stateio;
    getVector(in, a);
    getVector(in, b);
    getVector(in, shift);
    getVector(in, history);
    getVector(in, force);
    getVector(in, torqueA);
    getVector(in, torqueB);
    incidentStart.clear();
    incident.clear();
    slotsStale = true;
  }
  // The per-particle lists of a loaded state, built only once its indices have been validated
  // (Simulation::validateState): an index read from a file is never used before it is checked.
  void deriveAfterLoad(std::size_t nParticles) { buildIncidence(nParticles); }

 private:
  void buildIncidence(std::size_t n) {
    incidentStart.assign(n + 1, 0);
    for (std::size_t c = 0; c < size(); ++c) {
      ++incidentStart[a[c] + 1];
      if (!Kind::kPlane) ++incidentStart[b[c] + 1];
    }
    for (std::size_t i = 0; i < n; ++i) incidentStart[i + 1] += incidentStart[i];
    incident.resize(incidentStart[n]);
    std::vector<std::uint32_t> fill(incidentStart.begin(), incidentStart.end() - 1);
    for (std::size_t c = 0; c < size(); ++c) {
      incident[fill[a[c]]++] = static_cast<std::uint32_t>(2 * c);
      if (!Kind::kPlane) incident[fill[b[c]]++] = static_cast<std::uint32_t>(2 * c + 1);
    }
  }
};

// Every pair kind's list. A new shape adds its kinds here and in forEach, in a fixed order: the
// order in which a particle sums its contacts.
struct ContactStore {
  ContactList<SphereSphere> sphereSphere;
  ContactList<SpherePlane> sphereWall;
  ContactList<EllipsoidEllipsoid> ellipsoidEllipsoid;
  ContactList<SphereEllipsoid> sphereEllipsoid;
  ContactList<EllipsoidPlane> ellipsoidWall;

  template <class F>
  void forEach(F&& f) {
    f(sphereSphere);
    f(sphereWall);
    f(ellipsoidEllipsoid);
    f(sphereEllipsoid);
    f(ellipsoidWall);
  }
  template <class F>
  void forEach(F&& f) const {
    f(sphereSphere);
    f(sphereWall);
    f(ellipsoidEllipsoid);
    f(sphereEllipsoid);
    f(ellipsoidWall);
  }
  // The particle–particle kinds only.
  template <class F>
  void forEachPair(F&& f) {
    f(sphereSphere);
    f(ellipsoidEllipsoid);
    f(sphereEllipsoid);
  }
  template <class F>
  void forEachPair(F&& f) const {
    f(sphereSphere);
    f(ellipsoidEllipsoid);
    f(sphereEllipsoid);
  }
};

}  // namespace grainlab

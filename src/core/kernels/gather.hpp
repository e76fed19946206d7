#pragma once
// The gather as a per-particle kernel: particle i's force and torque, the sum of its contacts kind
// after kind (ContactStore::forEach order), each kind in the order of its CSR of incident contacts.
// No races (each particle sums only its own contacts) and a fixed order whatever the thread count:
// results are bit-identical for any number of threads.
#include <cstdint>
#include <type_traits>

#include "core/contact_list.hpp"
#include "core/types.hpp"

namespace grainlab::kernels {

struct Wrench {
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();
};

inline Wrench gatherParticle(const ContactStore& contacts, std::size_t i) {
  Wrench out;
  contacts.forEach([&](const auto& list) {
    using Kind = typename std::decay_t<decltype(list)>::KindType;
    for (std::uint32_t s = list.incidentStart[i]; s < list.incidentStart[i + 1]; ++s) {
      const std::uint32_t e = list.incident[s];
      const std::uint32_t c = e >> 1;
      if constexpr (Kind::kPlane) {  // the force of the wall on the particle
        out.force += list.force[c];
        out.torque += list.torqueA[c];
      } else if (e & 1u) {  // the particle is body B: the force of A on it
        out.force += list.force[c];
        out.torque += list.torqueB[c];
      } else {
        out.force -= list.force[c];
        out.torque += list.torqueA[c];
      }
    }
  });
  return out;
}

}  // namespace grainlab::kernels

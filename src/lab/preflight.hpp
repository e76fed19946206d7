#pragma once
// The up-front checks of a run (`grainlab check` and `grainlab run` make the same, before anything
// is allocated in bulk, prepared or written; docs/security.md): the memory the run needs against the
// machine's, the sample (drawn and placed as preparation's first step would, or the packing) with
// every derived parameter (masses, inertias, stiffnesses, rolling friction, critical time step)
// finite and normal, the time step against the critical one, and the steps of the test against
// solver.max_steps. Each refusal is an InputError naming the keys, the value and what is allowed.
#include <cstdint>

#include "core/simulation.hpp"
#include "lab/run_config.hpp"

namespace grainlab::lab {

// Rough peak memory of a run per particle: measured about 0.9 KB per particle during compaction
// (maximum resident size of runs of 1 000 to 32 000 particles: particles, contact lists with their
// history, the broad phase, and the copies the preparation keeps), doubled for the denser contact
// network of the prepared sample.
inline constexpr std::uint64_t kBytesPerParticle = 2048;
// Estimated peak memory of a run of n particles [bytes].
inline std::uint64_t estimatedRunBytes(std::uint64_t n) { return (64ull << 20) + n * kBytesPerParticle; }

// Every check above; `packed` is the packing of sample.packing (nullptr: the sample is prepared).
void preflight(const RunConfig& config, const Simulation* packed);

}  // namespace grainlab::lab

#pragma once
// The contact network of the engine's current state as the micromechanical analysis reads it
// (lab/micromechanics.hpp): particles by id, every touching contact with its normal, force and the
// branches to the contact point (periodic images resolved), the volume and the boundary's stress.
#include "core/simulation.hpp"
#include "lab/micromechanics.hpp"

namespace grainlab::lab {

MicroNetwork microNetwork(const Simulation& sim);

}  // namespace grainlab::lab

#pragma once
// Random loose placement of spheres without overlaps in a cubic box (LAB.md test 1).
#include <vector>

#include "core/particles.hpp"
#include "core/walls.hpp"
#include "lab/random.hpp"

namespace grainlab::lab {

// Places spheres of the given diameters [m] at random in a cube whose volume is
// (1 + voidRatio) times the solid volume, largest first, rejecting overlaps. The box grows by 5 %
// and placement restarts if a sphere finds no room. Particles are then renumbered in cell order,
// so that neighbours in space are neighbours in memory. Sets the walls on the cube's faces.
void placeLoose(std::vector<double> diameters, double density, double voidRatio, Rng& rng,
                Particles& particles, WallBox& box);

}  // namespace grainlab::lab

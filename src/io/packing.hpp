#pragma once
// Packing files: a prepared sample (walls and spheres) that a run can start from, that the bench
// caches, and that peer programs (bench/peer/yade_triaxial.py) read.
//
//   # free comment line
//   xlo xhi ylo yhi zlo zhi        wall planes [m]
//   radius x y z                   one sphere per line [m]
#include <filesystem>
#include <string>

#include "core/simulation.hpp"

namespace grainlab::io {

std::string packingText(const Simulation& sim, const std::string& comment);
// Replaces the particles and walls of `sim`; throws InputError naming the file and line on bad
// content.
void loadPacking(const std::filesystem::path& file, double density, Simulation& sim);

}  // namespace grainlab::io

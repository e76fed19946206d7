#pragma once
// Packing files: a prepared sample that a run can start from (sample.packing), that every run
// saves (packing.txt), that the bench caches and that peer programs read (bench/peer/yade_scene.py).
//
// Version 2 (written by grainlab; README "Packing files"):
//
//   # grainlab-packing 2
//   # program grainlab <version>
//   # comment <free text, one line>
//   # boundary walls                               (or: periodic)
//   # walls xlo xhi ylo yhi zlo zhi                (boundary walls) [m]
//   # cell h11 h12 h13 h21 h22 h23 h31 h32 h33     (boundary periodic) row-major H, columns = cell
//                                                  edge vectors, origin 0 [m]
//   # particles N
//   # columns id shape a b c x y z qw qx qy qz
//   # xxh64 <16 hex digits: xxh64 (seed 0) of every byte of the file except this line>
//   N rows: id (unsigned integer, unique), shape (sphere|ellipsoid), semi-axes a >= b >= c > 0 [m]
//   (sphere: a = b = c = radius), centre x y z [m], orientation quaternion qw qx qy qz (unit within
//   1e-6; identity for spheres, whose orientation is not used)
//
// Every header line is required except xxh64: a file written by hand without it is accepted after
// every other check (grainlab always writes it). The lines after the first may come in any order,
// but xxh64 must be the last. The checksum covers every byte but its own line (the header with the
// walls or cell, program and comment, and the rows). Version 1 (grainlab 0.1: a
// comment line, a line of six wall positions, then `radius x y z` rows) stays readable.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/simulation.hpp"

namespace grainlab::io {

struct PackedParticle {
  std::uint64_t id = 0;
  bool ellipsoid = false;
  Vec3 semiAxes = Vec3::Zero();  // a >= b >= c [m]
  Vec3 position = Vec3::Zero();  // [m]
  Quat orientation = Quat::Identity();
};

struct PackingData {
  int version = 2;         // of the file it was read from
  std::string program;     // "grainlab 0.1.0" (version 2 only)
  std::string comment;
  bool periodic = false;
  std::array<double, 6> walls{};  // xlo xhi ylo yhi zlo zhi [m] (walls)
  Mat3 cell = Mat3::Identity();   // columns = cell edge vectors [m] (periodic)
  std::vector<PackedParticle> particles;
};

// Version 2 text, checksum included.
std::string packingText(const PackingData& packing);
// Reads a packing file of version 1 or 2: a regular file of at most kMaxPackingBytes, every header
// key, count, number and the checksum validated. Throws InputError
// `config error: <key> = "<file>": line N: <what>` (key: the config key that named the file).
PackingData readPackingFile(const std::filesystem::path& file, const std::string& key);
// The same for text in memory; `subject` starts every message.
PackingData parsePacking(std::string_view text, const std::string& subject);

// Largest overlap a packing may hold between two grains, as a fraction of the smaller radius (of
// their inscribed spheres, c for an ellipsoid); coincident centres are refused always. Soft
// contacts in equilibrium overlap a lot: [O]'s stiffness number kappa = Kn/(p d) = 25 gives a mean
// overlap of ~4 % of a diameter and single contacts above 0.1 of the radius (0.12 measured on the
// grown spheres of tools/ouadfel_series.py, which a bound of 0.1 refused: grainlab refused its own
// packing). Half the radius is beyond any equilibrium packing a run can make and still refuses a
// garbage file's deep overlaps.
inline constexpr double kMaxPackingOverlap = 0.5;
// Refuses a packing that no run can start from: a grain outside the diameter bounds of
// lab::kMinDiameter..kMaxDiameter, a grain as large as its box or cell, and two grains overlapping
// by more than kMaxPackingOverlap (found with a spatial grid, O(n)). Messages name `subject`, the
// particle ids and what is allowed.
void checkPackingGeometry(const PackingData& packing, const std::string& subject);

// The grains (persistent ids, shapes, orientations) and the walls or cell of a simulation.
PackingData packingFromSimulation(const Simulation& sim, const std::string& comment);
// Replaces the particles and the boundary (walls or periodic cell) of `sim` with those of the
// packing; anything the engine cannot take is an InputError naming `subject`.
void simulationFromPacking(const PackingData& packing, double density, Simulation& sim, const std::string& subject);

}  // namespace grainlab::io

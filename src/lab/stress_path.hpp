#pragma once
// The table of a stress-path test (test.type = "stress-path", docs/laboratory.md "Stress paths"):
// points along a progress variable s, each giving per axis (x, y, z) a target and what it targets,
// a normal stress [Pa] or an engineering strain since the start of the path [-] (both compression
// positive). Between two points the targets move linearly in s; the test advances s at the test's
// rate (test.axial_strain_rate, s read as a strain).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace grainlab::lab {

enum class PathControl : std::uint8_t { Stress, Strain };

struct PathPoint {
  double s = 0.0;                         // progress variable at this point [-], > 0 and increasing
  std::array<double, 3> value{};          // x, y, z: stress [Pa] or strain [-]
  std::array<PathControl, 3> control{};   // what value is
};

// Bounds of a path (checked for the file and the inline form alike).
inline constexpr std::size_t kMaxPathPoints = 100'000;
inline constexpr double kMaxPathS = 10.0;
inline constexpr double kMaxPathStress = 1e10;  // [Pa]
inline constexpr double kMaxPathStrain = 0.5;   // |strain| of a target [-]

std::string_view controlName(PathControl c);
std::optional<PathControl> parseControl(std::string_view text);

// Why a point cannot follow the one before it (previousS: 0 for the first point), or "" when it
// can: s increasing and in (0, kMaxPathS], stresses in [0, kMaxPathStress] (grains carry no tension),
// strains in [-kMaxPathStrain, kMaxPathStrain], every value finite.
std::string checkPathPoint(const PathPoint& point, double previousS);

// (A path file is read with the config: io::readStressPathFile, io/list_files.hpp: comment lines
// start with '#', a header names the columns s, xx, xx_control, yy, yy_control, zz, zz_control in
// any order, then one point per line, each checked by checkPathPoint.)

}  // namespace grainlab::lab

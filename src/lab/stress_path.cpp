#include "lab/stress_path.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.hpp"
#include "io/input_file.hpp"

namespace grainlab::lab {

std::string_view controlName(PathControl c) { return c == PathControl::Stress ? "stress" : "strain"; }

std::optional<PathControl> parseControl(std::string_view text) {
  if (text == "stress") return PathControl::Stress;
  if (text == "strain") return PathControl::Strain;
  return std::nullopt;
}

std::string checkPathPoint(const PathPoint& p, double previousS) {
  if (!std::isfinite(p.s) || !(p.s > previousS) || p.s > kMaxPathS)
    return fmt::format("s = {} must be finite, above the previous point's s = {} and at most {}", p.s, previousS,
                       kMaxPathS);
  static constexpr const char* axes[3] = {"xx", "yy", "zz"};
  for (int a = 0; a < 3; ++a) {
    const double v = p.value[a];
    if (p.control[a] == PathControl::Stress && !(v >= 0.0 && v <= kMaxPathStress))
      return fmt::format("{} = {} must be a stress in [0, {:g}] [Pa] (compression positive; grains carry no tension)",
                         axes[a], v, kMaxPathStress);
    if (p.control[a] == PathControl::Strain && !(std::abs(v) <= kMaxPathStrain))
      return fmt::format("{} = {} must be a strain in [-{}, {}] (engineering strain since the start of the path, "
                         "compression positive)",
                         axes[a], v, kMaxPathStrain, kMaxPathStrain);
  }
  return "";
}



}  // namespace grainlab::lab

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

std::vector<PathPoint> readStressPathFile(const std::string& path, const std::string& key) {
  const std::string subject = fmt::format("config error: {} = {}", key, io::quotedPath(path));
  std::istringstream in(io::readInputFile(path, subject, io::kMaxListFileBytes));
  auto fail = [&](int line, const std::string& what) {
    return InputError(fmt::format("{}: {}{}", subject, line > 0 ? fmt::format("line {}: ", line) : std::string(), what));
  };
  static constexpr const char* kColumns[7] = {"s", "xx", "xx_control", "yy", "yy_control", "zz", "zz_control"};
  std::string line;
  int lineNo = 0;
  std::vector<std::string> header;
  while (header.empty() && std::getline(in, line)) {
    ++lineNo;
    if (!line.empty() && line[0] != '#' && line.find_first_not_of(" \t\r,") != std::string::npos)
      header = io::splitCsvLine(line);
  }
  std::array<int, 7> col{};
  for (int k = 0; k < 7; ++k) {
    const auto it = std::find(header.begin(), header.end(), kColumns[k]);
    if (it == header.end())
      throw fail(lineNo, fmt::format("the header has no column '{}' (expected s, xx, xx_control, yy, yy_control, zz, "
                                     "zz_control)", kColumns[k]));
    col[k] = static_cast<int>(it - header.begin());
  }
  std::vector<PathPoint> points;
  while (std::getline(in, line)) {
    ++lineNo;
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r,") == std::string::npos) continue;
    if (points.size() >= kMaxPathPoints) throw fail(lineNo, fmt::format("more than {} points", kMaxPathPoints));
    const std::vector<std::string> f = io::splitCsvLine(line);
    auto field = [&](int k) -> const std::string& {
      if (col[k] >= static_cast<int>(f.size())) throw fail(lineNo, fmt::format("missing {}", kColumns[k]));
      return f[col[k]];
    };
    auto number = [&](int k) {
      const std::string& text = field(k);
      try {
        std::size_t used = 0;
        const double v = std::stod(text, &used);
        if (used != text.size() || !std::isfinite(v)) throw std::invalid_argument("");
        return v;
      } catch (const std::exception&) {
        throw fail(lineNo, fmt::format("{} \"{}\" is not a finite number", kColumns[k], io::printable(text)));
      }
    };
    PathPoint p;
    p.s = number(0);
    for (int a = 0; a < 3; ++a) {
      const std::string& text = field(2 + 2 * a);
      const std::optional<PathControl> c = parseControl(text);
      if (!c)
        throw fail(lineNo, fmt::format("{} \"{}\" must be \"stress\" or \"strain\"", kColumns[2 + 2 * a], io::printable(text)));
      p.control[a] = *c;
      p.value[a] = number(1 + 2 * a);
    }
    if (const std::string why = checkPathPoint(p, points.empty() ? 0.0 : points.back().s); !why.empty())
      throw fail(lineNo, why);
    points.push_back(p);
  }
  if (points.empty()) throw fail(0, "no points (a header, then one line per point)");
  return points;
}

}  // namespace grainlab::lab

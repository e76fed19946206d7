#include "io/list_files.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <numeric>
#include <optional>
#include <sstream>
#include <string_view>

#include "core/errors.hpp"
#include "io/input_file.hpp"

namespace grainlab::io {

using namespace lab;  // the types these files fill

namespace {

// A number in a list file: the whole field (an optional '+' aside) must be one, and finite.
std::optional<double> listNumber(std::string_view field, bool& numeric) {
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), v);
  numeric = !field.empty() && end == field.data() + field.size() &&
            (ec == std::errc() || ec == std::errc::result_out_of_range);
  if (!numeric || ec != std::errc() || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace

std::vector<double> readDiameterList(const std::string& path) {
  const std::string subject = fmt::format("config error: sample.grading.file = {}", quotedPath(path));
  const std::string text = readInputFile(path, subject, kMaxListFileBytes);
  std::vector<double> out;
  std::size_t pos = 0;
  int lineNo = 0;
  bool header = false;  // the optional header line is past
  while (pos < text.size()) {
    const std::size_t nl = std::min(text.find('\n', pos), text.size());
    const std::string_view line(text.data() + pos, nl - pos);
    pos = nl + 1;
    ++lineNo;
    std::string_view field = line.substr(0, line.find(','));
    const auto b = field.find_first_not_of(" \t\r");
    if (b == std::string_view::npos || field[b] == '#') continue;
    field = field.substr(b, field.find_last_not_of(" \t\r") - b + 1);
    bool numeric = false;
    const std::optional<double> d = listNumber(field, numeric);
    // The one optional header: the first line that is not blank or a comment, if it has no digit at
    // all (e.g. "diameter_m"); "0.003abc" is a bad diameter, never a header.
    // "nan" and "inf" have no digit but are numbers (refused below as non-finite), not headers.
    auto isNumberWord = [](std::string_view f) {
      std::string lower;
      for (char ch : f)
        if (ch != '+' && ch != '-') lower += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      return lower == "nan" || lower == "inf" || lower == "infinity";
    };
    if (out.empty() && !header && field.find_first_of("0123456789") == std::string_view::npos && !isNumberWord(field)) {
      header = true;
      continue;
    }
    header = true;
    if (!d || !(*d >= kMinDiameter && *d <= kMaxDiameter))
      throw InputError(fmt::format("{}: line {}: \"{}\" is not a diameter in [{:g}, {:g}] m", subject, lineNo,
                                   printable(field), kMinDiameter, kMaxDiameter));
    out.push_back(*d);
  }
  if (out.empty()) throw InputError(fmt::format("{}: no diameters found", subject));
  return out;
}

lab::SphericityDistribution readSphericityFile(const std::string& path, const std::string& key) {
  const std::string subject = fmt::format("config error: {} = {}", key, quotedPath(path));
  std::istringstream in(readInputFile(path, subject, kMaxListFileBytes));
  auto fail = [&](int line, const std::string& what) {
    return InputError(fmt::format("{}: {}{}", subject, line > 0 ? fmt::format("line {}: ", line) : std::string(), what));
  };
  std::string line;
  int lineNo = 0;
  std::vector<std::string> header;
  while (header.empty() && std::getline(in, line)) {
    ++lineNo;
    if (!line.empty() && line[0] != '#') header = splitCsvLine(line);
  }
  auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    return it == header.end() ? -1 : static_cast<int>(it - header.begin());
  };
  const int psiCol = column("sphericity");
  const int lowCol = column("bin_low"), highCol = column("bin_high"), freqCol = column("frequency");
  if (psiCol < 0 && (lowCol < 0 || highCol < 0 || freqCol < 0))
    throw fail(lineNo, "expected a header with a column 'sphericity', or 'bin_low,bin_high,frequency'");
  lab::SphericityDistribution d;
  while (std::getline(in, line)) {
    ++lineNo;
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r,") == std::string::npos) continue;
    const std::vector<std::string> f = splitCsvLine(line);
    auto number = [&](int col, const char* name) {
      if (col >= static_cast<int>(f.size())) throw fail(lineNo, fmt::format("missing {}", name));
      try {
        std::size_t used = 0;
        const double v = std::stod(f[col], &used);
        if (used != f[col].size() || !std::isfinite(v)) throw std::invalid_argument("");
        return v;
      } catch (const std::exception&) {
        throw fail(lineNo, fmt::format("{} \"{}\" is not a finite number", name, printable(f[col])));
      }
    };
    if (psiCol >= 0) {
      const double psi = number(psiCol, "sphericity");
      if (!(psi > 0.0) || psi < DBL_MIN) throw fail(lineNo, fmt::format("sphericity {} must be > 0 (a normal number, >= 2.2e-308)", psi));
      d.values.push_back(psi);
      d.lines.push_back(lineNo);
    } else {
      const double lo = number(lowCol, "bin_low"), hi = number(highCol, "bin_high"), fr = number(freqCol, "frequency");
      if (!(lo >= DBL_MIN) || !(hi > lo))
        throw fail(lineNo, fmt::format("bin [{}, {}) must satisfy 0 < bin_low < bin_high (bin_low a normal number >= 2.2e-308)", lo, hi));
      if (fr < 0.0 || (fr > 0.0 && fr < DBL_MIN)) throw fail(lineNo, fmt::format("frequency {} must be >= 0 (0 or a normal number)", fr));
      d.lines.push_back(lineNo);
      d.binLow.push_back(lo);
      d.binHigh.push_back(hi);
      d.frequency.push_back(fr);
    }
  }
  if (d.values.empty() && d.frequency.empty()) throw fail(0, "no data rows");
  if (d.isHistogram() && std::accumulate(d.frequency.begin(), d.frequency.end(), 0.0) <= 0.0)
    throw fail(0, "all frequencies are zero");
  return d;
}

std::vector<lab::PathPoint> readStressPathFile(const std::string& path, const std::string& key) {
  const std::string subject = fmt::format("config error: {} = {}", key, quotedPath(path));
  std::istringstream in(readInputFile(path, subject, kMaxListFileBytes));
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
      header = splitCsvLine(line);
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
    const std::vector<std::string> f = splitCsvLine(line);
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
        throw fail(lineNo, fmt::format("{} \"{}\" is not a finite number", kColumns[k], printable(text)));
      }
    };
    PathPoint p;
    p.s = number(0);
    for (int a = 0; a < 3; ++a) {
      const std::string& text = field(2 + 2 * a);
      const std::optional<PathControl> c = parseControl(text);
      if (!c)
        throw fail(lineNo, fmt::format("{} \"{}\" must be \"stress\" or \"strain\"", kColumns[2 + 2 * a], printable(text)));
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

}  // namespace grainlab::io

#include "lab/grading.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <charconv>
#include <optional>
#include <string_view>

#include "core/errors.hpp"
#include "io/input_file.hpp"

namespace grainlab::lab {

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
  const std::string subject = fmt::format("config error: sample.grading.file = {}", io::quotedPath(path));
  const std::string text = io::readInputFile(path, subject, io::kMaxListFileBytes);
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
                                   io::printable(field), kMinDiameter, kMaxDiameter));
    out.push_back(*d);
  }
  if (out.empty()) throw InputError(fmt::format("{}: no diameters found", subject));
  return out;
}

std::vector<double> sampleDiameters(const GradingConfig& g, int n, Rng& rng) {
  std::vector<double> d(n);
  if (g.type == "uniform") {
    for (auto& v : d) v = rng.uniform(g.dMin, g.dMax);
  } else if (g.type == "list") {
    const std::vector<double> list = readDiameterList(g.file);
    if (static_cast<int>(list.size()) == n) {
      d = list;
    } else {
      for (auto& v : d) v = list[static_cast<std::size_t>(rng.uniform() * list.size())];
    }
  } else {
    // Segment k carries mass fraction dP_k uniformly over [d_k, d_k+1]; its number weight is
    // dP_k/(d_k+1 - d_k) * integral of d^-3 = dP_k/(d_k+1 - d_k) * (d_k^-2 - d_k+1^-2)/2.
    const auto& D = g.diameters;
    const auto& P = g.passing;
    std::vector<double> cumulative(D.size(), 0.0);
    for (std::size_t k = 0; k + 1 < D.size(); ++k) {
      const double w = (P[k + 1] - P[k]) / (D[k + 1] - D[k]) *
                       0.5 * (1.0 / (D[k] * D[k]) - 1.0 / (D[k + 1] * D[k + 1]));
      cumulative[k + 1] = cumulative[k] + w;
    }
    for (auto& v : d) {
      const double u = rng.uniform() * cumulative.back();
      std::size_t k = std::upper_bound(cumulative.begin(), cumulative.end(), u) - cumulative.begin() - 1;
      k = std::min(k, D.size() - 2);
      while (cumulative[k + 1] == cumulative[k] && k + 2 < D.size()) ++k;  // skip empty segments
      const double a = 1.0 / (D[k] * D[k]), b = 1.0 / (D[k + 1] * D[k + 1]);
      const double s = rng.uniform();
      v = 1.0 / std::sqrt(a - s * (a - b));
    }
  }
  return d;
}

double percentPassingDiameter(const std::vector<double>& sorted, double percent) {
  double total = 0.0;
  for (double d : sorted) total += d * d * d;
  double acc = 0.0;
  const double target = percent / 100.0 * total;
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    const double m = sorted[i] * sorted[i] * sorted[i];
    if (acc + m >= target) {
      // Interpolate within the class of this grain, between the previous and this diameter.
      const double prev = i > 0 ? sorted[i - 1] : sorted[i];
      const double f = m > 0.0 ? (target - acc) / m : 1.0;
      return prev + f * (sorted[i] - prev);
    }
    acc += m;
  }
  return sorted.back();
}

GradingStats gradingStats(std::vector<double> d) {
  std::sort(d.begin(), d.end());
  GradingStats s;
  s.d10 = percentPassingDiameter(d, 10);
  s.d30 = percentPassingDiameter(d, 30);
  s.d50 = percentPassingDiameter(d, 50);
  s.d60 = percentPassingDiameter(d, 60);
  s.cu = s.d60 / s.d10;
  s.cc = s.d30 * s.d30 / (s.d10 * s.d60);
  s.dMin = d.front();
  s.dMax = d.back();
  return s;
}

}  // namespace grainlab::lab

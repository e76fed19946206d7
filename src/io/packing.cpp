#include "io/packing.hpp"

#include <fmt/format.h>
#include <xxhash.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <optional>

#include "core/errors.hpp"
#include "io/input_file.hpp"
#include "lab/run_config.hpp"

namespace grainlab::io {

namespace {

constexpr std::string_view kColumns = "id shape a b c x y z qw qx qy qz";
// Most particles a packing may hold: the engine indexes particles with 32 bits, and
// sample.n_particles stops at the same bound.
constexpr std::uint64_t kMaxParticles = 50'000'000;
// A row has 12 fields, at least "0 sphere 1 1 1 0 0 0 1 0 0 0": no fewer bytes than this.
constexpr std::uint64_t kMinRowBytes = 28;

std::vector<std::string_view> fields(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t b = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > b) out.push_back(line.substr(b, i - b));
  }
  return out;
}

std::optional<double> finiteNumber(std::string_view token) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
  if (ec != std::errc() || end != token.data() + token.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<std::uint64_t> unsignedInteger(std::string_view token) {
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
  if (ec != std::errc() || end != token.data() + token.size()) return std::nullopt;
  return v;
}

// Lines of a text with their 1-based numbers and the offset just after each line's newline.
class Lines {
 public:
  explicit Lines(std::string_view text) : text_(text) {}
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    const std::size_t nl = text_.find('\n', pos_);
    const std::size_t end = nl == std::string_view::npos ? text_.size() : nl;
    line = text_.substr(pos_, end - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = nl == std::string_view::npos ? text_.size() : nl + 1;
    ++number_;
    return true;
  }
  int number() const { return number_; }
  std::size_t offset() const { return pos_; }  // start of the next line

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int number_ = 0;
};

class Parser {
 public:
  Parser(std::string_view text, std::string subject) : text_(text), subject_(std::move(subject)), lines_(text) {}

  PackingData parse() {
    std::string_view first;
    if (!lines_.next(first)) throw bad(0, "empty file");
    const std::vector<std::string_view> f = fields(first);
    if (f.size() >= 2 && f[0] == "#" && f[1] == "grainlab-packing") {
      if (f.size() == 3 && f[2] == "2") return parseVersion2();
      throw bad(1, fmt::format("packing format version {} is not supported; this grainlab reads versions 1 and 2",
                               f.size() > 2 ? printable(f[2]) : "(missing)"));
    }
    lines_ = Lines(text_);
    return parseVersion1();
  }

 private:
  InputError bad(int line, const std::string& what) const {
    return InputError(line > 0 ? fmt::format("{}: line {}: {}", subject_, line, what) : fmt::format("{}: {}", subject_, what));
  }

  template <std::size_t N>
  std::array<double, N> numbers(const std::vector<std::string_view>& f, std::size_t from, int line, const char* what) {
    if (f.size() != from + N) throw bad(line, fmt::format("expected {} numbers: {}", N, what));
    std::array<double, N> out{};
    for (std::size_t k = 0; k < N; ++k) {
      const auto v = finiteNumber(f[from + k]);
      if (!v) throw bad(line, fmt::format("\"{}\" is not a finite number ({})", printable(f[from + k]), what));
      out[k] = *v;
    }
    return out;
  }

  void checkWalls(const std::array<double, 6>& w, int line) {
    for (int a = 0; a < 3; ++a)
      if (!(w[2 * a + 1] > w[2 * a])) throw bad(line, "each upper wall must lie above its lower wall");
  }

  void checkInside(const PackingData& p, const Vec3& x, int line) {
    if (p.periodic) return;
    for (int a = 0; a < 3; ++a)
      if (!(x[a] > p.walls[2 * a] && x[a] < p.walls[2 * a + 1])) throw bad(line, "centre outside the walls");
  }

  // Grainlab 0.1: comment lines (#) anywhere, six wall positions, then `radius x y z` rows.
  PackingData parseVersion1() {
    PackingData p;
    p.version = 1;
    bool haveWalls = false;
    std::string_view line;
    while (lines_.next(line)) {
      const std::vector<std::string_view> f = fields(line);
      if (f.empty() || f[0].front() == '#') {
        if (!haveWalls && p.particles.empty() && p.comment.empty() && !f.empty())
          p.comment = std::string(line.substr(std::min(line.size(), line.find_first_not_of("# "))));
        continue;
      }
      if (!haveWalls) {
        p.walls = numbers<6>(f, 0, lines_.number(), "the wall positions xlo xhi ylo yhi zlo zhi");
        checkWalls(p.walls, lines_.number());
        haveWalls = true;
        continue;
      }
      const auto v = numbers<4>(f, 0, lines_.number(), "radius x y z [m]");
      if (!(v[0] > 0.0)) throw bad(lines_.number(), "the radius must be > 0 [m]");
      PackedParticle q;
      q.id = p.particles.size();
      q.semiAxes = Vec3::Constant(v[0]);
      q.position = Vec3(v[1], v[2], v[3]);
      checkInside(p, q.position, lines_.number());
      p.particles.push_back(q);
      if (p.particles.size() > kMaxParticles) throw bad(lines_.number(), fmt::format("more than {} particles", kMaxParticles));
    }
    if (!haveWalls) throw bad(0, "no wall positions (a version 1 packing starts with xlo xhi ylo yhi zlo zhi)");
    if (p.particles.empty()) throw bad(0, "no particles");
    return p;
  }

  PackingData parseVersion2() {
    PackingData p;
    std::map<std::string, int> seen;  // header key -> line
    std::optional<std::uint64_t> count, checksum;
    std::optional<std::string> boundary;
    bool walls = false, cell = false, columns = false;
    std::size_t bodyStart = lines_.offset(), checksumLine = 0;
    std::string_view line;
    // Header: '#' lines up to the first row; xxh64, when present, is the last of them.
    while (bodyStart < text_.size() && text_[bodyStart] == '#') {
      lines_.next(line);
      const int n = lines_.number();
      if (checksum) throw bad(n, "xxh64 must be the last header line");
      if (line.size() < 2 || line[1] != ' ') throw bad(n, "a header line is '# key value'");
      const std::string_view rest = line.substr(2);
      const std::string_view key = rest.substr(0, rest.find(' '));
      const std::string_view value = key.size() < rest.size() ? rest.substr(key.size() + 1) : std::string_view{};
      const std::string k(key);
      if (!seen.emplace(k, n).second) throw bad(n, fmt::format("header key \"{}\" given twice", printable(key)));
      const std::vector<std::string_view> f = fields(value);
      if (k == "program") {
        p.program = std::string(value);
      } else if (k == "comment") {
        p.comment = std::string(value);
      } else if (k == "boundary") {
        if (f.size() != 1 || (f[0] != "walls" && f[0] != "periodic"))
          throw bad(n, fmt::format("boundary \"{}\": allowed: walls, periodic", printable(value)));
        boundary = std::string(f[0]);
      } else if (k == "walls") {
        p.walls = numbers<6>(f, 0, n, "the wall positions xlo xhi ylo yhi zlo zhi [m]");
        checkWalls(p.walls, n);
        walls = true;
      } else if (k == "cell") {
        const auto h = numbers<9>(f, 0, n, "the cell matrix h11 h12 h13 h21 h22 h23 h31 h32 h33 [m]");
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) p.cell(r, c) = h[3 * r + c];
        if (!(p.cell.determinant() > 0.0)) throw bad(n, "the cell matrix must have det H > 0 (a right-handed cell)");
        cell = true;
      } else if (k == "particles") {
        count = f.size() == 1 ? unsignedInteger(f[0]) : std::nullopt;
        if (!count || *count < 1 || *count > kMaxParticles)
          throw bad(n, fmt::format("particles \"{}\": must be an integer in [1, {}]", printable(value), kMaxParticles));
      } else if (k == "columns") {
        std::string joined;
        for (const auto& x : f) {
          if (!joined.empty()) joined += ' ';
          joined.append(x);
        }
        if (joined != kColumns) throw bad(n, fmt::format("columns must be \"{}\"", kColumns));
        columns = true;
      } else if (k == "xxh64") {
        checksumLine = bodyStart;
        checksum = f.size() == 1 && f[0].size() == 16 ? std::optional<std::uint64_t>(0) : std::nullopt;
        if (checksum) {
          const auto [end, ec] = std::from_chars(f[0].data(), f[0].data() + 16, *checksum, 16);
          if (ec != std::errc() || end != f[0].data() + 16) checksum.reset();
        }
        if (!checksum) throw bad(n, fmt::format("xxh64 \"{}\": must be 16 hexadecimal digits", printable(value)));
      } else {
        throw bad(n, fmt::format("unknown header key \"{}\"; known: program, comment, boundary, walls, cell, particles, "
                                 "columns, xxh64",
                                 printable(key)));
      }
      bodyStart = lines_.offset();
    }
    const int headerEnd = lines_.number();
    if (!boundary) throw bad(headerEnd, "header key \"boundary\" missing (walls or periodic)");
    p.periodic = *boundary == "periodic";
    if (!p.periodic && !walls) throw bad(headerEnd, "header key \"walls\" missing (boundary walls)");
    if (p.periodic && !cell) throw bad(headerEnd, "header key \"cell\" missing (boundary periodic)");
    if (p.periodic && walls) throw bad(seen["walls"], "walls given for a periodic boundary");
    if (!p.periodic && cell) throw bad(seen["cell"], "cell given for a boundary of walls");
    if (!seen.count("program")) throw bad(headerEnd, "header key \"program\" missing (e.g. \"# program grainlab 0.1.0\")");
    if (!seen.count("comment")) throw bad(headerEnd, "header key \"comment\" missing (free text, may be empty)");
    if (!count) throw bad(headerEnd, "header key \"particles\" missing");
    if (!columns) throw bad(headerEnd, fmt::format("header key \"columns\" missing (\"{}\")", kColumns));
    const std::string_view body = text_.substr(bodyStart);
    if (checksum) {
      // Every byte of the file but the checksum's own line: the header before it and the rows.
      XXH64_state_t* state = XXH64_createState();
      XXH64_reset(state, 0);
      XXH64_update(state, text_.data(), checksumLine);
      XXH64_update(state, body.data(), body.size());
      const std::uint64_t actual = XXH64_digest(state);
      XXH64_freeState(state);
      if (actual != *checksum)
        throw bad(seen["xxh64"], fmt::format("checksum mismatch (stored {:016x}, computed {:016x}): the file is "
                                             "corrupted or was edited",
                                             *checksum, actual));
    }
    // The count is checked against the bytes there before anything is reserved for it.
    if (*count > (body.size() + 1) / (kMinRowBytes + 1) + 1)
      throw bad(seen["particles"], fmt::format("particles {} cannot fit in the {} bytes that follow the header", *count,
                                               body.size()));
    p.particles.reserve(static_cast<std::size_t>(*count));
    std::vector<std::pair<std::uint64_t, int>> ids;  // id, line
    ids.reserve(static_cast<std::size_t>(*count));
    while (lines_.next(line)) {
      const int n = lines_.number();
      const std::vector<std::string_view> f = fields(line);
      if (f.empty()) continue;
      if (f[0].front() == '#') throw bad(n, "a header line after the particle rows");
      if (p.particles.size() == *count) throw bad(n, fmt::format("more rows than the {} particles of the header", *count));
      if (f.size() != 12) throw bad(n, fmt::format("expected 12 columns ({}), found {}", kColumns, f.size()));
      PackedParticle q;
      const auto id = unsignedInteger(f[0]);
      if (!id) throw bad(n, fmt::format("id \"{}\" is not an unsigned integer", printable(f[0])));
      q.id = *id;
      if (f[1] != "sphere" && f[1] != "ellipsoid")
        throw bad(n, fmt::format("shape \"{}\": allowed: sphere, ellipsoid", printable(f[1])));
      q.ellipsoid = f[1] == "ellipsoid";
      const auto v = numbers<10>(f, 2, n, "a b c x y z qw qx qy qz");
      q.semiAxes = Vec3(v[0], v[1], v[2]);
      if (!(v[2] > 0.0) || v[0] < v[1] || v[1] < v[2]) throw bad(n, "semi-axes must satisfy a >= b >= c > 0 [m]");
      if (!q.ellipsoid && !(v[0] == v[1] && v[1] == v[2])) throw bad(n, "a sphere has a = b = c (its radius)");
      q.position = Vec3(v[3], v[4], v[5]);
      checkInside(p, q.position, n);
      q.orientation = Quat(v[6], v[7], v[8], v[9]);
      if (!(std::abs(q.orientation.norm() - 1.0) <= 1e-6))
        throw bad(n, "the orientation quaternion must be a unit quaternion (within 1e-6)");
      p.particles.push_back(q);
      ids.emplace_back(q.id, n);
    }
    if (p.particles.size() != *count)
      throw bad(lines_.number(), fmt::format("{} particle rows, the header says {}", p.particles.size(), *count));
    std::sort(ids.begin(), ids.end());
    for (std::size_t i = 1; i < ids.size(); ++i)
      if (ids[i].first == ids[i - 1].first)
        throw bad(std::max(ids[i].second, ids[i - 1].second), fmt::format("id {} is not unique", ids[i].first));
    return p;
  }

  std::string_view text_;
  std::string subject_;
  Lines lines_;
};

// One line of free text for a header.
std::string oneLine(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

}  // namespace

std::string packingText(const PackingData& p) {
  std::string body;
  body.reserve(p.particles.size() * 220);
  for (const PackedParticle& q : p.particles) {
    const Quat& o = q.orientation;
    body += fmt::format("{} {} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g}\n", q.id,
                        q.ellipsoid ? "ellipsoid" : "sphere", q.semiAxes[0], q.semiAxes[1], q.semiAxes[2],
                        q.position[0], q.position[1], q.position[2], o.w(), o.x(), o.y(), o.z());
  }
  std::string s = "# grainlab-packing 2\n";
  s += fmt::format("# program grainlab {}\n", GRAINLAB_VERSION);
  s += "# comment " + oneLine(p.comment) + "\n";
  if (p.periodic) {
    s += "# boundary periodic\n# cell";
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) s += fmt::format(" {:.17g}", p.cell(r, c));
    s += "\n";
  } else {
    s += "# boundary walls\n# walls";
    for (double w : p.walls) s += fmt::format(" {:.17g}", w);
    s += "\n";
  }
  s += fmt::format("# particles {}\n# columns {}\n", p.particles.size(), kColumns);
  // The checksum covers every byte but its own line: the header above it and the rows below.
  const std::string covered = s + body;
  s += fmt::format("# xxh64 {:016x}\n", XXH64(covered.data(), covered.size(), 0));
  return s + body;
}

PackingData parsePacking(std::string_view text, const std::string& subject) { return Parser(text, subject).parse(); }

PackingData readPackingFile(const std::filesystem::path& file, const std::string& key) {
  const std::string subject = fmt::format("config error: {} = {}", key, quotedPath(file));
  return parsePacking(readInputFile(file, subject, kMaxPackingBytes), subject);
}

PackingData packingFromSimulation(const Simulation& sim, const std::string& comment) {
  PackingData p;
  p.program = std::string("grainlab ") + GRAINLAB_VERSION;
  p.comment = comment;
  p.periodic = sim.boundary == Boundary::Periodic;
  if (p.periodic) p.cell = sim.cell.h;
  else
    for (int k = 0; k < 6; ++k) p.walls[k] = sim.box.walls[k].position;
  const Particles& P = sim.particles;
  p.particles.resize(P.size());
  for (std::size_t i = 0; i < P.size(); ++i) {
    PackedParticle& q = p.particles[i];
    q.id = P.id[i];
    q.ellipsoid = P.shape[i] == Shape::Ellipsoid;
    q.semiAxes = P.semiAxes[i];
    q.position = P.position[i];
    q.orientation = P.orientation[i];
  }
  return p;
}

void checkPackingGeometry(const PackingData& p, const std::string& subject) {
  const std::size_t n = p.particles.size();
  if (n == 0) return;
  // Box or cell widths (a cell: its volume over the area of each pair of edges).
  Vec3 width;
  if (p.periodic) {
    const double volume = p.cell.determinant();
    for (int k = 0; k < 3; ++k)
      width[k] = volume / p.cell.col((k + 1) % 3).cross(p.cell.col((k + 2) % 3)).norm();
  } else {
    for (int k = 0; k < 3; ++k) width[k] = p.walls[2 * k + 1] - p.walls[2 * k];
  }
  double inscribedMax = 0.0;
  for (const PackedParticle& q : p.particles) {
    const double a = q.semiAxes[0], c = q.semiAxes[2];
    if (!(2.0 * c >= lab::kMinDiameter && 2.0 * a <= lab::kMaxDiameter))
      throw InputError(fmt::format("{}: particle id {}: semi-axes ({:g}, {:g}, {:g}) m; allowed: diameters in [{:g}, {:g}] m",
                                   subject, q.id, q.semiAxes[0], q.semiAxes[1], c, lab::kMinDiameter, lab::kMaxDiameter));
    if (!(2.0 * a < width.minCoeff()))
      throw InputError(fmt::format("{}: particle id {}: its size 2a = {:g} m is not smaller than its {} (smallest width "
                                   "{:g} m); allowed: grains smaller than the box",
                                   subject, q.id, 2.0 * a, p.periodic ? "cell" : "box of walls", width.minCoeff()));
    inscribedMax = std::max(inscribedMax, c);
  }
  // Grid of cells at least 2 x the largest inscribed radius wide (pairs that overlap are in
  // neighbouring cells), in fractional coordinates of the box or cell, at most ~n cells.
  const Mat3 inverse = p.periodic ? Mat3(p.cell.inverse()) : Mat3::Identity();
  const Vec3 lo = p.periodic ? Vec3::Zero() : Vec3(p.walls[0], p.walls[2], p.walls[4]);
  double h = 2.0 * inscribedMax;
  std::array<long, 3> m{};
  for (;;) {
    double cells = 1.0;
    for (int k = 0; k < 3; ++k) cells *= (m[k] = std::max(1L, static_cast<long>(std::floor(width[k] / h))));
    if (cells <= 2.0 * static_cast<double>(n) + 27.0) break;
    h *= 1.5;
  }
  std::vector<Vec3> frac(n);
  std::vector<std::array<long, 3>> cellOf(n);
  std::vector<std::size_t> key(n);
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 s;
    if (p.periodic) {
      s = inverse * p.particles[i].position;
      for (int k = 0; k < 3; ++k) s[k] -= std::floor(s[k]);
    } else {
      s = (p.particles[i].position - lo).cwiseQuotient(width);
    }
    frac[i] = s;
    for (int k = 0; k < 3; ++k) cellOf[i][k] = std::clamp(static_cast<long>(s[k] * static_cast<double>(m[k])), 0L, m[k] - 1);
    key[i] = static_cast<std::size_t>((cellOf[i][0] * m[1] + cellOf[i][1]) * m[2] + cellOf[i][2]);
  }
  // Counting sort of the particles by cell.
  const std::size_t cells = static_cast<std::size_t>(m[0] * m[1] * m[2]);
  std::vector<std::size_t> start(cells + 1, 0), order(n);
  for (std::size_t i = 0; i < n; ++i) ++start[key[i] + 1];
  for (std::size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) order[fill[key[i]]++] = i;
  }
  auto neighbours = [&](int k, long c) {
    std::vector<long> out;
    for (long d = -1; d <= 1; ++d) {
      long v = c + d;
      if (p.periodic) v = ((v % m[k]) + m[k]) % m[k];
      else if (v < 0 || v >= m[k]) continue;
      if (std::find(out.begin(), out.end(), v) == out.end()) out.push_back(v);
    }
    return out;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const PackedParticle& A = p.particles[i];
    for (long x : neighbours(0, cellOf[i][0]))
      for (long y : neighbours(1, cellOf[i][1]))
        for (long z : neighbours(2, cellOf[i][2])) {
          const std::size_t c = static_cast<std::size_t>((x * m[1] + y) * m[2] + z);
          for (std::size_t o = start[c]; o < start[c + 1]; ++o) {
            const std::size_t j = order[o];
            if (j <= i) continue;
            const PackedParticle& B = p.particles[j];
            Vec3 d;
            if (p.periodic) {
              Vec3 ds = frac[j] - frac[i];
              for (int k = 0; k < 3; ++k) ds[k] -= std::round(ds[k]);
              d = p.cell * ds;
            } else {
              d = B.position - A.position;
            }
            const double ra = A.semiAxes[2], rb = B.semiAxes[2];
            const double overlap = ra + rb - d.norm();
            if (overlap > kMaxPackingOverlap * std::min(ra, rb))
              throw InputError(fmt::format(
                  "{}: particles id {} and id {} overlap by {:.3g} m ({:.3g} of the smaller {}radius {:.6g} m{}); allowed: "
                  "overlaps up to {} of the smaller radius (a packing in equilibrium)",
                  subject, A.id, B.id, overlap, overlap / std::min(ra, rb), A.ellipsoid || B.ellipsoid ? "inscribed " : "",
                  std::min(ra, rb), d.norm() == 0.0 ? ", coincident centres" : "", kMaxPackingOverlap));
          }
        }
  }
}

void simulationFromPacking(const PackingData& p, double density, Simulation& sim, const std::string& subject) {
  if (p.particles.size() < 2) throw InputError(fmt::format("{}: fewer than two particles", subject));
  Particles particles;
  for (const PackedParticle& q : p.particles) {
    if (q.ellipsoid) particles.addEllipsoid(q.position, q.semiAxes, q.orientation, density, q.id);
    else particles.addSphere(q.position, q.semiAxes[0], density, q.id);
  }
  sim.particles = std::move(particles);
  if (p.periodic) {
    sim.boundary = Boundary::Periodic;
    sim.cell.h = p.cell;
    sim.cell.refresh();
    sim.cell.referenceLength = p.cell.diagonal();
  } else {
    sim.boundary = Boundary::Walls;
    sim.box.setBounds(Vec3(p.walls[0], p.walls[2], p.walls[4]), Vec3(p.walls[1], p.walls[3], p.walls[5]));
  }
}

}  // namespace grainlab::io

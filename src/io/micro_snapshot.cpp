#include "io/micro_snapshot.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <set>
#include <unordered_map>

#include "core/errors.hpp"
#include "io/results.hpp"

namespace grainlab::io {

namespace fs = std::filesystem;

namespace {

const char* const kIndexHeader = "index,step,eps1,volume,sxx,syy,szz,sxy,sxz,syz";
const char* const kParticlesHeader = "id,shape,x,y,z,a,b,c,ux,uy,uz,frictionless";
const char* const kContactsHeader = "a,b,nx,ny,nz,fx,fy,fz,ax,ay,az,bx,by,bz";
constexpr std::size_t kMaxLine = 4096;  // longer lines are refused (a valid row is < 500 chars)
constexpr double kUnitTolerance = 1e-6;  // |n| and |u| must be 1 within this

std::string g17(double v) { return fmt::format("{:.17g}", v); }

std::string snapshotName(const char* kind, int index) { return fmt::format("{}_{:04d}.csv", kind, index); }

std::string cut(const std::string& s) { return s.size() > 80 ? s.substr(0, 77) + "..." : s; }

// Reads one CSV file with a fixed header, row by row; every complaint names the file and line.
class CsvReader {
 public:
  CsvReader(const fs::path& file, const std::string& header) : file_(file) {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) fail0(fs::exists(file, ec) ? "is not a regular file" : "does not exist");
    in_.open(file, std::ios::binary);
    if (!in_) fail0("cannot be read");
    names_ = split(header);
    if (!readLine()) fail(fmt::format("empty file, expected the header '{}'", header));
    if (text_ != header) fail(fmt::format("header '{}' is not '{}'", cut(text_), header));
  }

  // Next data row (blank lines skipped); false at the end of the file.
  bool next() {
    while (readLine())
      if (!text_.empty()) {
        fields_ = split(text_);
        if (fields_.size() != names_.size())
          fail(fmt::format("expected {} comma-separated fields ({}), found {}", names_.size(), cut(join(names_)),
                           fields_.size()));
        return true;
      }
    return false;
  }

  const std::string& field(std::size_t i) const { return fields_[i]; }
  bool empty(std::size_t i) const { return fields_[i].empty(); }

  double number(std::size_t i) const {
    const std::string& s = fields_[i];
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v))
      failField(i, "must be a finite number");
    return v;
  }
  std::optional<double> optionalNumber(std::size_t i) const {
    if (empty(i)) return std::nullopt;
    return number(i);
  }
  std::int64_t integer(std::size_t i, const std::string& s) const {
    std::int64_t v = 0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || ptr != s.data() + s.size() || v < 0)
      failField(i, "must be a non-negative integer");
    return v;
  }
  std::int64_t integer(std::size_t i) const { return integer(i, fields_[i]); }

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("{}: line {}: {}", file_.string(), line_, what));
  }
  [[noreturn]] void failField(std::size_t i, const std::string& allowed) const {
    fail(fmt::format("{} = '{}': {}", names_[i], cut(fields_[i]), allowed));
  }
  int line() const { return line_; }

 private:
  [[noreturn]] void fail0(const std::string& what) const { throw InputError(fmt::format("{}: {}", file_.string(), what)); }

  bool readLine() {
    char buffer[kMaxLine + 1];
    in_.getline(buffer, sizeof buffer);
    if (in_.eof() && in_.gcount() == 0) return false;
    ++line_;
    if (in_.fail() && !in_.eof()) fail(fmt::format("line longer than {} characters", kMaxLine));
    text_.assign(buffer);
    if (!text_.empty() && text_.back() == '\r') text_.pop_back();
    if (in_.eof()) in_.clear(std::ios::eofbit);  // a last line without newline is still a line
    return true;
  }
  static std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out(1);
    for (char c : s) {
      if (c == ',') out.emplace_back();
      else out.back() += c;
    }
    return out;
  }
  static std::string join(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
    return s;
  }

  fs::path file_;
  std::ifstream in_;
  std::vector<std::string> names_, fields_;
  std::string text_;
  int line_ = 0;
};

Vec3 vec(const CsvReader& r, std::size_t first) { return {r.number(first), r.number(first + 1), r.number(first + 2)}; }

void requireUnit(const CsvReader& r, std::size_t first, const Vec3& v, const char* what) {
  if (std::abs(v.norm() - 1.0) > kUnitTolerance)
    r.fail(fmt::format("{} ({}, {}, {}) must be a unit vector (|{}| = {:.9g})", what, cut(r.field(first)),
                       cut(r.field(first + 1)), cut(r.field(first + 2)), what, v.norm()));
}

}  // namespace

std::string microIndexCsv(const std::vector<MicroSnapshotInfo>& snapshots) {
  std::string s = std::string(kIndexHeader) + "\n";
  for (const auto& i : snapshots) {
    s += fmt::format("{},{},{},{}", i.index, i.step, g17(i.eps1), g17(i.volume));
    if (i.stress) {
      const Mat3& t = *i.stress;
      for (double v : {t(0, 0), t(1, 1), t(2, 2), t(0, 1), t(0, 2), t(1, 2)}) s += fmt::format(",{:.17g}", v);
    } else {
      s += ",,,,,,";
    }
    s += '\n';
  }
  return s;
}

std::string microParticlesCsv(const lab::MicroNetwork& network) {
  std::string s = std::string(kParticlesHeader) + "\n";
  for (const auto& p : network.particles) {
    const Vec3& x = p.centre;
    s += fmt::format("{},", p.id);
    if (p.shape == lab::MicroParticle::Shape::Sphere) {
      s += fmt::format("sphere,{},{},{},{},,,,,,", g17(x[0]), g17(x[1]), g17(x[2]), g17(p.radius));
    } else {
      const Vec3& a = p.semiAxes;
      const Vec3& u = p.longAxis;
      s += fmt::format("ellipsoid,{},{},{},{},{},{},{},{},{},", g17(x[0]), g17(x[1]), g17(x[2]), g17(a[0]), g17(a[1]),
                       g17(a[2]), g17(u[0]), g17(u[1]), g17(u[2]));
    }
    s += p.frictionless ? "1\n" : "0\n";
  }
  return s;
}

std::string microContactsCsv(const lab::MicroNetwork& network) {
  std::string s = std::string(kContactsHeader) + "\n";
  for (const auto& c : network.contacts) {
    s += fmt::format("{},{}", c.a, c.wall ? fmt::format("w{}", c.b) : fmt::format("{}", c.b));
    for (const Vec3* v : {&c.normal, &c.force, &c.branchA})
      s += fmt::format(",{},{},{}", g17((*v)[0]), g17((*v)[1]), g17((*v)[2]));
    s += c.wall ? ",,,\n" : fmt::format(",{},{},{}\n", g17(c.branchB[0]), g17(c.branchB[1]), g17(c.branchB[2]));
  }
  return s;
}

void MicroSnapshotSeries::write(const lab::MicroNetwork& network, long step, double eps1) {
  MicroSnapshotInfo info;
  info.index = static_cast<int>(snapshots_.size());
  info.step = step;
  info.eps1 = eps1;
  info.volume = network.volume;
  info.stress = network.measuredStress;
  writeFileAtomic(dir_ / snapshotName("particles", info.index), microParticlesCsv(network));
  writeFileAtomic(dir_ / snapshotName("contacts", info.index), microContactsCsv(network));
  snapshots_.push_back(info);
  writeFileAtomic(dir_ / "snapshots.csv", microIndexCsv(snapshots_));
}

std::vector<MicroSnapshotInfo> readMicroIndex(const fs::path& dir) {
  CsvReader r(dir / "snapshots.csv", kIndexHeader);
  std::vector<MicroSnapshotInfo> out;
  std::set<int> seen;
  while (r.next()) {
    MicroSnapshotInfo i;
    const std::int64_t index = r.integer(0);
    if (index > 9999) r.failField(0, "must be at most 9999 (files are numbered NNNN)");
    i.index = static_cast<int>(index);
    if (!seen.insert(i.index).second) r.failField(0, "appears twice");
    i.step = static_cast<long>(r.integer(1));
    i.eps1 = r.number(2);
    i.volume = r.number(3);
    if (!(i.volume > 0.0)) r.failField(3, "must be positive [m^3]");
    int given = 0;
    for (std::size_t f = 4; f < 10; ++f) given += r.empty(f) ? 0 : 1;
    if (given == 6) {
      Mat3 s;
      s(0, 0) = r.number(4), s(1, 1) = r.number(5), s(2, 2) = r.number(6);
      s(0, 1) = s(1, 0) = r.number(7);
      s(0, 2) = s(2, 0) = r.number(8);
      s(1, 2) = s(2, 1) = r.number(9);
      i.stress = s;
    } else if (given != 0) {
      r.fail("the stress needs all six components sxx..syz, or none (not measured)");
    }
    out.push_back(i);
  }
  return out;
}

lab::MicroNetwork readMicroSnapshot(const fs::path& dir, const MicroSnapshotInfo& info) {
  lab::MicroNetwork net;
  net.volume = info.volume;
  net.measuredStress = info.stress;
  std::unordered_map<std::int64_t, std::size_t> ids;
  {
    CsvReader r(dir / snapshotName("particles", info.index), kParticlesHeader);
    while (r.next()) {
      lab::MicroParticle p;
      p.id = r.integer(0);
      if (!ids.emplace(p.id, net.particles.size()).second) r.failField(0, "appears twice");
      p.centre = vec(r, 2);
      if (r.field(1) == "sphere") {
        p.radius = r.number(5);
        if (!(p.radius > 0.0)) r.failField(5, "sphere radius must be positive [m]");
        for (std::size_t f = 6; f <= 10; ++f)
          if (!r.empty(f)) r.failField(f, "must be empty for a sphere");
      } else if (r.field(1) == "ellipsoid") {
        p.shape = lab::MicroParticle::Shape::Ellipsoid;
        p.semiAxes = vec(r, 5);
        if (!(p.semiAxes[2] > 0.0 && p.semiAxes[1] >= p.semiAxes[2] && p.semiAxes[0] >= p.semiAxes[1]))
          r.fail(fmt::format("semi-axes a, b, c = {}, {}, {} must satisfy a >= b >= c > 0 [m]", cut(r.field(5)),
                             cut(r.field(6)), cut(r.field(7))));
        p.longAxis = vec(r, 8);
        requireUnit(r, 8, p.longAxis, "long axis u");
      } else {
        r.failField(1, "must be 'sphere' or 'ellipsoid'");
      }
      if (r.field(11) != "0" && r.field(11) != "1") r.failField(11, "must be 0 or 1");
      p.frictionless = r.field(11) == "1";
      net.particles.push_back(p);
    }
    if (net.particles.empty()) r.fail("no particles");
  }
  CsvReader r(dir / snapshotName("contacts", info.index), kContactsHeader);
  while (r.next()) {
    lab::MicroContact c;
    c.a = r.integer(0);
    if (!ids.count(c.a)) r.failField(0, "is not a particle id of the snapshot");
    const std::string& b = r.field(1);
    if (!b.empty() && b[0] == 'w') {
      c.wall = true;
      c.b = r.integer(1, b.substr(1));
    } else {
      c.b = r.integer(1);
      if (!ids.count(c.b)) r.failField(1, "is not a particle id of the snapshot, nor wK for wall K");
      if (c.b == c.a) r.failField(1, "is the same particle as a");
    }
    c.normal = vec(r, 2);
    requireUnit(r, 2, c.normal, "normal n");
    c.force = vec(r, 5);
    c.branchA = vec(r, 8);
    if (c.wall) {
      for (std::size_t f = 11; f <= 13; ++f)
        if (!r.empty(f)) r.failField(f, "must be empty for a wall contact");
    } else {
      c.branchB = vec(r, 11);
    }
    net.contacts.push_back(c);
  }
  return net;
}

nlohmann::json microSnapshotsJson(const std::vector<MicroSnapshotInfo>& snapshots) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& s : snapshots) {
    nlohmann::json stress = nullptr;
    if (s.stress) {
      stress = nlohmann::json::array();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) stress.push_back((*s.stress)(i, j));
    }
    list.push_back({{"index", s.index}, {"step", s.step}, {"eps1", s.eps1}, {"volume", s.volume}, {"stress", stress}});
  }
  return list;
}

std::vector<MicroSnapshotInfo> microSnapshotsFromJson(const nlohmann::json& list, const std::string& where) {
  auto bad = [&](const std::string& what) {
    return InputError(fmt::format("{}: micro_snapshots: {}", where, what));
  };
  if (!list.is_array()) throw bad("not a list");
  std::vector<MicroSnapshotInfo> out;
  for (const auto& e : list) {
    auto number = [&](const char* key) {
      if (!e.is_object() || !e.contains(key) || !e[key].is_number() || !std::isfinite(e[key].get<double>()))
        throw bad(fmt::format("entry {}: \"{}\" missing or not a finite number", out.size(), key));
      return e[key].get<double>();
    };
    MicroSnapshotInfo info;
    info.index = static_cast<int>(number("index"));
    info.step = static_cast<long>(number("step"));
    info.eps1 = number("eps1");
    info.volume = number("volume");
    if (info.index != static_cast<int>(out.size())) throw bad(fmt::format("entry {}: index {} out of order", out.size(), info.index));
    const nlohmann::json& st = e.value("stress", nlohmann::json());
    if (!st.is_null()) {
      if (!st.is_array() || st.size() != 9) throw bad(fmt::format("entry {}: stress is not 9 numbers", out.size()));
      Mat3 m;
      for (int k = 0; k < 9; ++k) {
        if (!st[k].is_number() || !std::isfinite(st[k].get<double>()))
          throw bad(fmt::format("entry {}: stress component {} is not a finite number", out.size(), k));
        m(k / 3, k % 3) = st[k].get<double>();
      }
      info.stress = m;
    }
    out.push_back(info);
  }
  return out;
}

}  // namespace grainlab::io

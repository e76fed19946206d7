#include "io/checkpoint_file.hpp"

#include <fmt/format.h>
#include <xxhash.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>

#include "core/errors.hpp"
#include "core/simulation.hpp"
#include "core/state_io.hpp"
#include "io/config.hpp"
#include "io/input_file.hpp"
#include "lab/protocols.hpp"

namespace grainlab::io {

namespace {

constexpr char kMagic[8] = {'G', 'L', 'C', 'K', 'P', 'T', '\0', '\n'};
constexpr std::size_t kHeaderBytes = 80;
constexpr std::size_t kVersionBytes = 32;
constexpr std::size_t kChecksumBytes = 8;

template <class T>
void putLE(std::string& out, T value) {
  static_assert(std::endian::native == std::endian::little, "checkpoints are written little-endian");
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}
template <class T>
T getLE(std::string_view bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

std::string hex(std::uint64_t v) { return fmt::format("{:016x}", v); }

}  // namespace

std::uint64_t stateLayoutTag() {
  using stateio::fieldCount;
  // Everything whose size or field list shapes the bytes of Laboratory::saveState.
  const std::array<std::uint64_t, 25> shape{
      kCheckpointFormat,
      fieldCount<Particles>(),
      sizeof(Wall),
      fieldCount<Wall>(),
      sizeof(WallBox),
      sizeof(contact::SphereContactModel),
      fieldCount<contact::SphereContactModel>(),
      sizeof(ServoSettings),
      fieldCount<ServoSettings>(),
      sizeof(EnergyLedger),
      fieldCount<EnergyLedger>(),
      fieldCount<contact::ContactHistory>(),
      sizeof(lab::Record),
      fieldCount<lab::Record>(),
      sizeof(BroadPhase),
      sizeof(Simulation),
      fieldCount<PeriodicCell>(),
      fieldCount<lab::GrainRecords>(),
      sizeof(ContactList<SphereSphere>),
      sizeof(ContactStore),
      lab::Record::kMicroColumns,
      sizeof(lab::ProtocolState),
      fieldCount<lab::ProtocolState>(),
      lab::Laboratory::shearStateFieldCount(),
      fieldCount<Membrane>(),
  };
  return XXH64(shape.data(), sizeof(shape), 0);
}

std::uint64_t configHash(const lab::RunConfig& config) {
  lab::RunConfig c = config;
  c.output.dir.clear();
  const std::string text = toTomlString(resolvedTable(c));
  return XXH64(text.data(), text.size(), 0);
}

std::string encodeCheckpoint(const lab::RunConfig& config, const nlohmann::json& record, const std::string& state) {
  const std::string meta = record.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string out(kMagic, sizeof(kMagic));
  putLE<std::uint32_t>(out, kCheckpointFormat);
  putLE<std::uint32_t>(out, 0);
  putLE<std::uint64_t>(out, stateLayoutTag());
  putLE<std::uint64_t>(out, configHash(config));
  std::string version = GRAINLAB_VERSION;
  version.resize(kVersionBytes, '\0');
  out += version;
  putLE<std::uint64_t>(out, meta.size());
  putLE<std::uint64_t>(out, state.size());
  out.reserve(out.size() + meta.size() + state.size() + kChecksumBytes);
  out += meta;
  out += state;
  putLE<std::uint64_t>(out, XXH64(out.data(), out.size(), 0));
  return out;
}

Checkpoint decodeCheckpoint(std::string_view bytes, const std::filesystem::path& file) {
  auto refuse = [&](const std::string& why) {
    return InputError(fmt::format("checkpoint {}: {}", quotedPath(file), why));
  };
  if (!bytes.empty() && bytes[0] == '{')
    throw refuse("an earlier checkpoint format (grainlab-checkpoint-2) that this grainlab does not read; run again");
  if (bytes.size() < kHeaderBytes + kChecksumBytes)
    throw refuse(fmt::format("truncated ({} bytes; the header alone has {})", bytes.size(), kHeaderBytes + kChecksumBytes));
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) throw refuse("not a grainlab checkpoint (wrong magic bytes)");
  const auto format = getLE<std::uint32_t>(bytes, 8);
  if (format != kCheckpointFormat)
    throw refuse(fmt::format("checkpoint format {}; this grainlab reads format {}", format, kCheckpointFormat));
  const auto metaSize = getLE<std::uint64_t>(bytes, 64);
  const auto stateSize = getLE<std::uint64_t>(bytes, 72);
  const std::uint64_t body = bytes.size() - kHeaderBytes - kChecksumBytes;
  if (metaSize > body || stateSize > body - metaSize || metaSize + stateSize != body)
    throw refuse(fmt::format("sizes do not match the file (header: {} + {} bytes of content, file: {}): truncated or "
                             "corrupted",
                             metaSize, stateSize, body));
  const auto stored = getLE<std::uint64_t>(bytes, bytes.size() - kChecksumBytes);
  const std::uint64_t actual = XXH64(bytes.data(), bytes.size() - kChecksumBytes, 0);
  if (stored != actual)
    throw refuse(fmt::format("checksum mismatch (stored {}, computed {}): the file is corrupted", hex(stored), hex(actual)));
  if (getLE<std::uint32_t>(bytes, 12) != 0) throw refuse("corrupted header (reserved field not 0)");

  Checkpoint c;
  c.layoutTag = getLE<std::uint64_t>(bytes, 16);
  c.configHash = getLE<std::uint64_t>(bytes, 24);
  const std::string_view version = bytes.substr(32, kVersionBytes);
  c.programVersion = std::string(version.substr(0, version.find('\0')));
  for (char ch : c.programVersion)
    if (ch < 0x20 || ch > 0x7e) throw refuse("corrupted header (program version is not text)");
  try {
    c.record = nlohmann::json::parse(bytes.substr(kHeaderBytes, metaSize));
  } catch (const nlohmann::json::exception&) {
    throw refuse("corrupted run record (not JSON)");
  }
  const auto& r = c.record;
  bool ok = r.is_object() && r.contains("summary") && r["summary"].is_object() && r.contains("vtk_labels") &&
            r["vtk_labels"].is_array() && r.contains("wall_seconds") && r["wall_seconds"].is_number() &&
            std::isfinite(r["wall_seconds"].get<double>()) && r["wall_seconds"].get<double>() >= 0.0;
  if (ok)
    for (const auto& v : r["vtk_labels"]) ok = ok && v.is_number() && std::isfinite(v.get<double>());
  if (!ok) throw refuse("corrupted run record (summary, vtk_labels or wall_seconds missing or invalid)");
  c.state = std::string(bytes.substr(kHeaderBytes + metaSize, stateSize));
  return c;
}

Checkpoint readCheckpointFile(const std::filesystem::path& file) {
  // The header's sizes are checked against the file's length and this machine's memory before the
  // rest is read: a sparse file of tens of GiB (or a header that claims it) is refused at once
  // rather than read whole.
  const auto vet = [&](std::string_view head, std::uintmax_t size) {
    auto refuse = [&](const std::string& why) {
      return InputError(fmt::format("checkpoint {}: {}", quotedPath(file), why));
    };
    if (!head.empty() && head[0] == '{') return;  // an earlier format: decodeCheckpoint names it
    if (head.size() < kHeaderBytes) return;        // truncated: decodeCheckpoint names it
    if (std::memcmp(head.data(), kMagic, sizeof(kMagic)) != 0) throw refuse("not a grainlab checkpoint (wrong magic bytes)");
    const auto metaSize = getLE<std::uint64_t>(head, 64);
    const auto stateSize = getLE<std::uint64_t>(head, 72);
    const std::uintmax_t body = size - std::min<std::uintmax_t>(size, kHeaderBytes + kChecksumBytes);
    if (metaSize > body || stateSize > body - metaSize || metaSize + stateSize != body)
      throw refuse(fmt::format("sizes do not match the file (header: {} + {} bytes of content, file: {}): truncated or "
                               "corrupted",
                               metaSize, stateSize, body));
    const std::uintmax_t memory = physicalMemoryBytes();
    if (memory > 0 && size > memory / 2)
      throw refuse(fmt::format("{} bytes, more than half of this machine's memory ({} bytes): not read", size, memory));
  };
  const std::string bytes =
      readInputFile(file, fmt::format("checkpoint {}", quotedPath(file)), kMaxCheckpointBytes, kHeaderBytes, vet);
  return decodeCheckpoint(bytes, file);
}

void checkCheckpointBelongs(const Checkpoint& c, const std::filesystem::path& file, const lab::RunConfig& config,
                            bool allowOlderVersion) {
  auto refuse = [&](const std::string& why) {
    return InputError(fmt::format("checkpoint {}: {}", quotedPath(file), why));
  };
  const int order = compareVersions(c.programVersion, GRAINLAB_VERSION);
  if (order != 0 && !(allowOlderVersion && order < 0))
    throw refuse(fmt::format("written by grainlab {}, this is grainlab {}{}", printable(c.programVersion),
                             GRAINLAB_VERSION,
                             order < 0 ? " (resume --allow-older-version accepts it when the checkpoint format is the same)"
                                       : ""));
  if (c.layoutTag != stateLayoutTag())
    throw refuse(fmt::format("written by a grainlab build with another engine state layout (layout {}, this build {})",
                             hex(c.layoutTag), hex(stateLayoutTag())));
  if (c.configHash != configHash(config))
    throw refuse(fmt::format("belongs to another config (config hash {}, the config.resolved.toml beside it gives {})",
                             hex(c.configHash), hex(configHash(config))));
}

int compareVersions(std::string_view a, std::string_view b) {
  auto next = [](std::string_view& s) {
    long v = 0;
    std::size_t i = 0;
    while (i < s.size() && s[i] != '.') {
      if (s[i] >= '0' && s[i] <= '9' && v < 100'000'000) v = 10 * v + (s[i] - '0');
      ++i;
    }
    s.remove_prefix(std::min(s.size(), i + 1));
    return v;
  };
  while (!a.empty() || !b.empty()) {
    const long x = next(a), y = next(b);
    if (x != y) return x < y ? -1 : 1;
  }
  return 0;
}

}  // namespace grainlab::io

#pragma once
// The checkpoint container (checkpoint/state.bin): what `resume` trusts only after checking it.
//
//   offset  size  content
//        0     8  magic "GLCKPT\0\n"
//        8     4  format version (kCheckpointFormat), little-endian like every number here
//       12     4  reserved, 0
//       16     8  layout tag: sizes and field counts of the engine structs in the state
//       24     8  xxh64 of the resolved config (output.dir left out: a folder may be moved)
//       32    32  program version, ASCII, NUL-padded
//       64     8  M: size of the run record (JSON: summary so far, VTK snapshot labels, wall time)
//       72     8  S: size of the engine state (Laboratory::saveState)
//       80     M  run record
//     80+M     S  engine state
//   80+M+S     8  xxh64 (seed 0) of every byte before it
//
// A file that is truncated, corrupted (checksum), of another format or layout, written by another
// program version or for another config is refused with an InputError naming the file and what
// differs.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <nlohmann/json.hpp>

#include "lab/run_config.hpp"

namespace grainlab::io {

inline constexpr std::uint32_t kCheckpointFormat = 3;

struct Checkpoint {
  std::string programVersion;
  std::uint64_t layoutTag = 0;
  std::uint64_t configHash = 0;
  nlohmann::json record;  // {"summary": {...}, "vtk_labels": [...], "wall_seconds": s}
  std::string state;
};

// The layout tag of this build.
std::uint64_t stateLayoutTag();
// xxh64 of the resolved config with output.dir left out.
std::uint64_t configHash(const lab::RunConfig& config);

// A checkpoint of this program and build for `config`.
std::string encodeCheckpoint(const lab::RunConfig& config, const nlohmann::json& record, const std::string& state);
// Checks magic, format, sizes, checksum and the run record; throws InputError naming `file`.
Checkpoint decodeCheckpoint(std::string_view bytes, const std::filesystem::path& file);
// Reads (a regular file, size-bounded) and decodes.
Checkpoint readCheckpointFile(const std::filesystem::path& file);
// Whether a checkpoint may be resumed by this program with `config`: same program version (with
// allowOlderVersion: an older one is accepted too), same state layout, same config. Throws
// InputError naming `file` and what differs.
void checkCheckpointBelongs(const Checkpoint& checkpoint, const std::filesystem::path& file,
                            const lab::RunConfig& config, bool allowOlderVersion);

// Compares dotted version numbers ("0.10.0" > "0.9.1"); a part that is not a number compares as 0.
int compareVersions(std::string_view a, std::string_view b);

}  // namespace grainlab::io

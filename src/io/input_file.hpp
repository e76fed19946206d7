#pragma once
// Reading files a user hands to grainlab (configs, list files, packings, checkpoints) within stated
// limits, and echoing user values in error messages safely. docs/security.md lists the limits.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace grainlab::io {

// Size limits, checked before a file is read.
inline constexpr std::uintmax_t kMaxConfigBytes = std::uintmax_t{1} << 20;     // TOML config: 1 MiB
inline constexpr std::uintmax_t kMaxListFileBytes = std::uintmax_t{64} << 20;  // grading list, sphericity CSV
inline constexpr std::uintmax_t kMaxPackingBytes = std::uintmax_t{1} << 30;    // packing file: 1 GiB
inline constexpr std::uintmax_t kMaxCheckpointBytes = std::uintmax_t{32} << 30;
// Deepest nesting of a TOML config or --set value (tables, arrays, inline tables), checked before
// the parser sees it (the parser and the printer of `check` recurse once per level).
inline constexpr int kMaxNesting = 64;
// Longest echo of a user's value in a message (the value is cut with "...").
inline constexpr std::size_t kEchoChars = 80;

// A file-system failure (exit code 1): the message names the path and the system's reason.
struct FileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// "what PATH: strerror(err)", for a FileError.
std::string fileErrorMessage(const std::string& what, const std::filesystem::path& path, int err);

// Reads the whole of a regular file of at most maxBytes. Anything else (a directory, a device such
// as /dev/zero, a FIFO, a missing or unreadable file, a larger file) is an InputError
// "<subject>: <reason>", so `subject` names the key and the file, e.g.
// `config error: sample.grading.file = "grains.csv"`.
std::string readInputFile(const std::filesystem::path& path, const std::string& subject, std::uintmax_t maxBytes);
// The same, in two steps: `vet(head, size)` sees the first headBytes (or fewer) and the file's size
// before the rest is read, and throws to refuse it (e.g. sizes in a header that the file's length or
// this machine's memory cannot hold), so a huge or sparse file is never read whole on trust.
std::string readInputFile(const std::filesystem::path& path, const std::string& subject, std::uintmax_t maxBytes,
                          std::size_t headBytes,
                          const std::function<void(std::string_view head, std::uintmax_t size)>& vet);

// The fields of one line of a CSV list file (no quoting: the files grainlab reads hold numbers and
// words), each trimmed of spaces, tabs and a trailing carriage return.
std::vector<std::string> splitCsvLine(const std::string& line);

// Physical memory of this machine [bytes] (0 when the system does not say).
std::uintmax_t physicalMemoryBytes();

// A user's text as it may appear inside a one-line message: control characters and bytes that are
// not UTF-8 escaped (\n, \x1b, \xff), cut to about maxChars characters with "...".
std::string printable(std::string_view text, std::size_t maxChars = kEchoChars);
// A path for a message: printable(path) in double quotes.
std::string quotedPath(const std::filesystem::path& path);

}  // namespace grainlab::io

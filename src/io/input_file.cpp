#include "io/input_file.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <algorithm>
#include <cstring>
#include <sstream>

#include "core/errors.hpp"

namespace grainlab::io {

std::string fileErrorMessage(const std::string& what, const std::filesystem::path& path, int err) {
  return fmt::format("{} {}: {}", what, quotedPath(path), std::strerror(err));
}

namespace {

const char* kindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// Closes the descriptor on every path out of readInputFile.
struct Descriptor {
  int fd;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::string readInputFile(const std::filesystem::path& path, const std::string& subject, std::uintmax_t maxBytes) {
  return readInputFile(path, subject, maxBytes, 0, {});
}

std::string readInputFile(const std::filesystem::path& path, const std::string& subject, std::uintmax_t maxBytes,
                          std::size_t headBytes,
                          const std::function<void(std::string_view head, std::uintmax_t size)>& vet) {
  auto refuse = [&](const std::string& why) { return InputError(fmt::format("{}: {}", subject, why)); };
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer; it has no effect on
  // the regular files that are read.
  const Descriptor file{::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY)};
  if (file.fd < 0) throw refuse(errno == ENOENT ? "file not found" : std::strerror(errno));
  struct stat st {};
  if (::fstat(file.fd, &st) != 0) throw refuse(std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw refuse(fmt::format("{}; a regular file is required", kindOf(st.st_mode)));
  const auto size = static_cast<std::uintmax_t>(st.st_size);
  if (size > maxBytes) throw refuse(fmt::format("{} bytes, more than the limit of {} bytes", size, maxBytes));
  auto readInto = [&](std::string& content, std::size_t from) {
    std::size_t done = from;
    while (done < content.size()) {
      const ssize_t n = ::read(file.fd, content.data() + done, content.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw refuse(std::strerror(errno));
      if (n == 0) break;  // shrank while being read: parse what is there
      done += static_cast<std::size_t>(n);
    }
    content.resize(done);
  };
  std::string content;
  std::size_t from = 0;
  if (vet) {
    content.assign(static_cast<std::size_t>(std::min<std::uintmax_t>(headBytes, size)), '\0');
    readInto(content, 0);
    vet(content, size);
    from = content.size();
  }
  content.resize(static_cast<std::size_t>(size), '\0');
  readInto(content, from);
  return content;
}

std::uintmax_t physicalMemoryBytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long pageSize = ::sysconf(_SC_PAGESIZE);
  if (pages <= 0 || pageSize <= 0) return 0;
  return static_cast<std::uintmax_t>(pages) * static_cast<std::uintmax_t>(pageSize);
}

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string field;
  while (std::getline(ss, field, ',')) {
    const auto b = field.find_first_not_of(" \t\r");
    const auto e = field.find_last_not_of(" \t\r");
    out.push_back(b == std::string::npos ? "" : field.substr(b, e - b + 1));
  }
  return out;
}

std::string printable(std::string_view text, std::size_t maxChars) {
  std::string out;
  std::size_t chars = 0;
  std::size_t i = 0;
  while (i < text.size()) {
    if (chars >= maxChars) {
      out += "...";
      break;
    }
    const auto c = static_cast<unsigned char>(text[i]);
    // Length of a well-formed UTF-8 sequence starting here (0: not one).
    std::size_t len = 0;
    if (c >= 0x20 && c < 0x7f) {
      len = 1;
    } else if (c >= 0xc2 && c <= 0xf4) {
      const std::size_t want = c < 0xe0 ? 2 : c < 0xf0 ? 3 : 4;
      bool ok = i + want <= text.size();
      for (std::size_t k = 1; ok && k < want; ++k) ok = (static_cast<unsigned char>(text[i + k]) & 0xc0) == 0x80;
      if (ok && want >= 3) {
        const auto c1 = static_cast<unsigned char>(text[i + 1]);
        // No overlong forms, no surrogates, nothing above U+10FFFF.
        ok = !(c == 0xe0 && c1 < 0xa0) && !(c == 0xed && c1 >= 0xa0) && !(c == 0xf0 && c1 < 0x90) &&
             !(c == 0xf4 && c1 >= 0x90);
      }
      if (ok) len = want;
    }
    // Code points that are valid but act on the display (C1 controls, zero-width and bidirectional
    // marks such as U+202E, which reverses what follows) are escaped too.
    char32_t cp = 0;
    if (len > 1) {
      cp = c & (0x7f >> len);
      for (std::size_t k = 1; k < len; ++k) cp = (cp << 6) | (static_cast<unsigned char>(text[i + k]) & 0x3f);
    }
    if (len > 1 && ((cp >= 0x80 && cp <= 0x9f) || (cp >= 0x200b && cp <= 0x200f) || (cp >= 0x202a && cp <= 0x202e) ||
                    (cp >= 0x2066 && cp <= 0x2069) || cp == 0xfeff)) {
      out += fmt::format("\\u{:04x}", static_cast<unsigned>(cp));
      i += len;
    } else if (len > 0) {
      out.append(text.substr(i, len));
      i += len;
    } else {
      switch (c) {
        case '\n': out += "\\n"; break;
        case '\r': out += "\\r"; break;
        case '\t': out += "\\t"; break;
        default: out += fmt::format("\\x{:02x}", c);
      }
      ++i;
    }
    ++chars;
  }
  return out;
}

// Paths are longer than values and their end (the file name) matters: a longer limit.
std::string quotedPath(const std::filesystem::path& path) { return fmt::format("\"{}\"", printable(path.native(), 240)); }

}  // namespace grainlab::io

#pragma once
// Exact binary (de)serialisation of the engine state for checkpoints: every double is written as
// its bytes, so a resumed run continues bit for bit. The layout belongs to one build; the
// checkpoint container (io/checkpoint_file.hpp) guards it with a format version, a layout tag, the
// sizes and a checksum.
//
// What may be written, checked at compile time for every value:
//   - arithmetic types and enums, and structs that are trivially copyable (only plain values
//     inside: a struct holding a std::vector is not trivially copyable and does not compile);
//   - bool, as one byte that must read back as 0 or 1;
//   - Eigen's Vec3 and Quat, component by component (they are not trivially copyable);
//   - contact::ContactHistory, field by field (it holds Vec3s);
//   - std::array and std::vector of any of these (a vector as a 64-bit count, then the elements);
//   - structs that list their fields (`Listed`: a static `fields(self)` returning std::tie of every
//     field, in the order of the bytes), field by field through that one list, so writing and
//     reading cannot disagree and a field added without listing it does not compile.
// Reading is bounded: loadState reads from a MemoryInput, and every count is checked against the
// bytes left before anything is allocated.
#include <array>
#include <cstdint>
#include <cstring>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <streambuf>
#include <tuple>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "contact/models.hpp"
#include "core/types.hpp"

namespace grainlab::stateio {

// A malformed state (truncated, a count beyond the bytes left, an invalid value).
struct StateError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A read-only stream over bytes in memory: the only kind of stream loadState accepts, since the
// bytes left must be known before a count read from the file is trusted.
class MemoryInput : public std::istream {
 public:
  explicit MemoryInput(std::string_view bytes) : std::istream(&buffer_), buffer_(bytes) {}
  std::size_t bytesLeft() const { return buffer_.left(); }

 private:
  struct Buffer : std::streambuf {
    explicit Buffer(std::string_view b) {
      char* begin = const_cast<char*>(b.data());  // never written through: get area only
      setg(begin, begin, begin + b.size());
    }
    std::size_t left() const { return static_cast<std::size_t>(egptr() - gptr()); }
  };
  Buffer buffer_;
};

namespace detail {
inline std::size_t bytesLeft(std::istream& in) {
  const auto* memory = dynamic_cast<const MemoryInput*>(&in);
  if (!memory) throw std::logic_error("checkpoint state must be read from a stateio::MemoryInput");
  return memory->bytesLeft();
}
// A MemoryInput cannot read past its end: a short read leaves the stream failed.
inline void readBytes(std::istream& in, void* to, std::size_t n) {
  if (!in.read(static_cast<char*>(to), static_cast<std::streamsize>(n))) throw StateError("state truncated");
}
}  // namespace detail

// Values written as their bytes: plain values with nothing pointing elsewhere.
template <class T>
concept Bytewise = std::is_trivially_copyable_v<T> && !std::is_pointer_v<T> && !std::is_member_pointer_v<T> &&
                   !std::is_same_v<T, bool>;

// Number of fields of an aggregate (how many initialisers T{...} accepts): lets tests and static
// assertions notice a field added to a struct whose writer lists its fields by hand.
namespace detail {
struct AnyField {
  template <class U>
  operator U() const;
};
template <class T, class... A>
constexpr std::size_t fieldCount() {
  if constexpr (requires { T{A{}..., AnyField{}}; })
    return fieldCount<T, A..., AnyField>();
  else
    return sizeof...(A);
}
}  // namespace detail
template <class T>
constexpr std::size_t fieldCount() {
  static_assert(std::is_aggregate_v<T>);
  return detail::fieldCount<T>();
}

template <Bytewise T>
void put(std::ostream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}
template <Bytewise T>
void get(std::istream& in, T& value) {
  detail::readBytes(in, &value, sizeof(T));
}

// A struct with padding, written as its bytes (the layout `get` reads back) but with the padding
// as zeros: `put` copies whatever the padding holds (uninitialised stack or heap bytes), so two
// saves of equal states could differ, and those bytes would end up in the file. Every field must
// be listed (checked against fieldCount).
template <class T, class... M>
void putFields(std::ostream& out, const T& value, M T::*... fields) {
  static_assert(std::is_trivially_copyable_v<T>);
  static_assert(fieldCount<T>() == sizeof...(M), "list every field of the struct");
  alignas(T) unsigned char bytes[sizeof(T)] = {};
  const auto* base = reinterpret_cast<const unsigned char*>(&value);
  (std::memcpy(bytes + (reinterpret_cast<const unsigned char*>(&(value.*fields)) - base), &(value.*fields), sizeof(M)),
   ...);
  out.write(reinterpret_cast<const char*>(bytes), sizeof(T));
}

inline void put(std::ostream& out, bool value) { put(out, static_cast<std::uint8_t>(value ? 1 : 0)); }
inline void get(std::istream& in, bool& value) {
  std::uint8_t b = 0;
  get(in, b);
  if (b > 1) throw StateError("state corrupt (a flag is neither 0 nor 1)");
  value = b == 1;
}

inline void put(std::ostream& out, const Vec3& v) {
  for (int k = 0; k < 3; ++k) put(out, v[k]);
}
inline void get(std::istream& in, Vec3& v) {
  for (int k = 0; k < 3; ++k) get(in, v[k]);
}
inline void put(std::ostream& out, const Quat& q) {
  put(out, q.w());
  put(out, q.x());
  put(out, q.y());
  put(out, q.z());
}
inline void get(std::istream& in, Quat& q) {
  double c[4];
  for (double& v : c) get(in, v);
  q = Quat(c[0], c[1], c[2], c[3]);
}

inline void put(std::ostream& out, const Mat3& m) {
  for (int k = 0; k < 9; ++k) put(out, m(k % 3, k / 3));
}
inline void get(std::istream& in, Mat3& m) {
  for (int k = 0; k < 9; ++k) get(in, m(k % 3, k / 3));
}

static_assert(fieldCount<contact::ContactHistory>() == 5,
              "a field was added to ContactHistory: write and read it below");
inline void put(std::ostream& out, const contact::ContactHistory& h) {
  put(out, h.shearForce);
  put(out, h.moment);
  put(out, h.prevNormal);
  put(out, h.overlap);
  put(out, h.touching);
}
inline void get(std::istream& in, contact::ContactHistory& h) {
  get(in, h.shearForce);
  get(in, h.moment);
  get(in, h.prevNormal);
  get(in, h.overlap);
  get(in, h.touching);
}

static_assert(fieldCount<contact::EllipsoidHistory>() == 3, "a field was added to EllipsoidHistory: write and read it below");
inline void put(std::ostream& out, const contact::EllipsoidHistory& h) {
  put(out, static_cast<const contact::ContactHistory&>(h));
  put(out, h.lambda);
  put(out, h.potentialLength);
}
inline void get(std::istream& in, contact::EllipsoidHistory& h) {
  get(in, static_cast<contact::ContactHistory&>(h));
  get(in, h.lambda);
  get(in, h.potentialLength);
}

// Bytes one element occupies in the state (for the bounds check of a vector's count).
template <class T>
constexpr std::size_t encodedSize() {
  if constexpr (std::is_same_v<T, bool>) return 1;
  else if constexpr (std::is_same_v<T, Vec3>) return 3 * sizeof(double);
  else if constexpr (std::is_same_v<T, Quat>) return 4 * sizeof(double);
  else if constexpr (std::is_same_v<T, Mat3>) return 9 * sizeof(double);
  else if constexpr (std::is_same_v<T, contact::ContactHistory>) return 10 * sizeof(double) + 1;
  else if constexpr (std::is_same_v<T, contact::EllipsoidHistory>) return 12 * sizeof(double) + 1;
  else return sizeof(T);
}

template <class T, std::size_t N>
void put(std::ostream& out, const std::array<T, N>& a) {
  for (const T& v : a) put(out, v);
}
template <class T, std::size_t N>
void get(std::istream& in, std::array<T, N>& a) {
  for (T& v : a) get(in, v);
}

template <class T>
void putVector(std::ostream& out, const std::vector<T>& v) {
  put(out, static_cast<std::uint64_t>(v.size()));
  if constexpr (Bytewise<T>) {
    if (!v.empty()) out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
  } else {
    for (const T& e : v) put(out, e);
  }
}

template <class T>
void getVector(std::istream& in, std::vector<T>& v) {
  std::uint64_t n = 0;
  get(in, n);
  // Before anything is allocated: the count must fit in the bytes that are left.
  if (n > detail::bytesLeft(in) / encodedSize<T>()) throw StateError("state corrupt (a count exceeds the bytes left)");
  v.resize(static_cast<std::size_t>(n));
  if constexpr (Bytewise<T>) {
    if (n) detail::readBytes(in, v.data(), static_cast<std::size_t>(n) * sizeof(T));
  } else {
    for (T& e : v) get(in, e);
  }
}

// A struct that names its fields once, for writing and reading: `static auto fields(Self& s)`
// returns std::tie(s.a, s.b, ...) of every field (Self const or not).
template <class T>
concept Listed = !Bytewise<T> && requires(T& v, const T& c) {
  T::fields(v);
  T::fields(c);
};

template <class T>
void put(std::ostream& out, const std::vector<T>& v) {
  putVector(out, v);
}
template <class T>
void get(std::istream& in, std::vector<T>& v) {
  getVector(in, v);
}

template <Listed T>
void put(std::ostream& out, const T& value) {
  static_assert(fieldCount<T>() == std::tuple_size_v<decltype(T::fields(value))>,
                "list every field of the struct in its fields()");
  std::apply([&out](const auto&... field) { (put(out, field), ...); }, T::fields(value));
}
template <Listed T>
void get(std::istream& in, T& value) {
  static_assert(fieldCount<T>() == std::tuple_size_v<decltype(T::fields(value))>,
                "list every field of the struct in its fields()");
  std::apply([&in](auto&... field) { (get(in, field), ...); }, T::fields(value));
}

}  // namespace grainlab::stateio

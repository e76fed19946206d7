#pragma once
// Exact binary (de)serialisation of the engine state for checkpoints: every double is written as
// its bytes, so a resumed run continues bit for bit. Only trivially copyable values and vectors of
// them pass through here; the layout is private to one grainlab version (a version tag guards it).
#include <cstdint>
#include <istream>
#include <ostream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace grainlab::stateio {

// Values copied as bytes: trivially copyable types, and the fixed-size Eigen vectors and
// quaternions (and structs of them), which are plain arrays of doubles with no pointers inside
// even though their copy constructors are user-provided.
template <class T>
constexpr bool kBitwise = std::is_trivially_copyable_v<T> || std::is_standard_layout_v<T>;

template <class T>
void put(std::ostream& out, const T& value) {
  static_assert(kBitwise<T>);
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <class T>
void get(std::istream& in, T& value) {
  static_assert(kBitwise<T>);
  if (!in.read(reinterpret_cast<char*>(&value), sizeof(T))) throw std::runtime_error("checkpoint truncated");
}

template <class T>
void putVector(std::ostream& out, const std::vector<T>& v) {
  put(out, static_cast<std::uint64_t>(v.size()));
  if (!v.empty()) out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(T)));
}

template <class T>
void getVector(std::istream& in, std::vector<T>& v) {
  static_assert(kBitwise<T>);
  std::uint64_t n = 0;
  get(in, n);
  if (n > (std::uint64_t{1} << 40)) throw std::runtime_error("checkpoint corrupt (vector size)");
  v.resize(n);
  if (n && !in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T))))
    throw std::runtime_error("checkpoint truncated");
}

}  // namespace grainlab::stateio

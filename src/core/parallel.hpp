#pragma once
// Deterministic parallel sums. The work is cut into fixed chunks; each chunk's partial sum is
// stored under its chunk index and the partials are added in chunk order. The result is the same
// for any thread count and any schedule, so loops whose iterations cost unequal amounts (touching
// vs. non-touching pairs) can use dynamic scheduling without losing bit-reproducibility. (OpenMP's
// reduction clause combines partials in completion order instead.)
#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

namespace grainlab {

class ChunkedSums {
 public:
  static constexpr std::size_t kChunk = 512;

  ChunkedSums() = default;
  ChunkedSums(std::size_t items, int terms) { reset(items, terms); }
  // Re-cuts the sums for `items` items and `terms` terms per chunk (keeps the storage; every
  // chunk's terms must be written again before they are read).
  void reset(std::size_t items, int terms) {
    items_ = items;
    terms_ = terms;
    values_.assign(chunks() * terms, 0.0);
  }
  std::size_t chunks() const { return (items_ + kChunk - 1) / kChunk; }
  std::size_t begin(std::size_t chunk) const { return chunk * kChunk; }
  std::size_t end(std::size_t chunk) const { return std::min(items_, (chunk + 1) * kChunk); }
  double& at(std::size_t chunk, int term) { return values_[chunk * terms_ + term]; }
  double total(int term) const {
    double s = 0.0;
    for (std::size_t c = 0; c < values_.size() / terms_; ++c) s += values_[c * terms_ + term];
    return s;
  }
  double maxOf(int term) const {
    double m = -std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < values_.size() / terms_; ++c) m = std::max(m, values_[c * terms_ + term]);
    return m;
  }
  double minOf(int term) const {
    double m = std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < values_.size() / terms_; ++c) m = std::min(m, values_[c * terms_ + term]);
    return m;
  }

 private:
  std::size_t items_ = 0;
  int terms_ = 1;
  std::vector<double> values_;
};

}  // namespace grainlab

#pragma once
// Seeded random numbers whose sequence is fixed by the C++ standard (mt19937_64) and turned into
// doubles here, so a seed gives the same sample with any standard library.
#include <cstdint>
#include <random>

namespace grainlab::lab {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

 private:
  std::mt19937_64 engine_;
};

}  // namespace grainlab::lab

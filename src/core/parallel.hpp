#pragma once
// Deterministic parallel reductions: each thread accumulates its static chunk, and the partial sums
// are added in thread order. OpenMP's reduction clause combines partials in completion order, which
// would make the last bits of a sum vary from run to run.
#include <omp.h>

#include <vector>

namespace grainlab {

class ThreadPartials {
 public:
  explicit ThreadPartials(int terms) : terms_(terms), values_(omp_get_max_threads() * terms, 0.0) {}
  double* of(int thread) { return &values_[static_cast<std::size_t>(thread) * terms_]; }
  double total(int term) const {
    double s = 0.0;
    for (std::size_t t = 0; t < values_.size() / terms_; ++t) s += values_[t * terms_ + term];
    return s;
  }

 private:
  int terms_;
  std::vector<double> values_;
};

}  // namespace grainlab

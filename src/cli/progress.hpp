#pragma once
// Progress line for long phases on a terminal: phase, percent, steps/s, ETA. Silent when stderr is
// not a terminal or with --quiet.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace grainlab::cli {

class ProgressLine {
 public:
  explicit ProgressLine(bool quiet) : enabled_(!quiet && ::isatty(STDERR_FILENO)) {}
  ~ProgressLine() { finish(); }

  void update(const std::string& phase, double fraction, long steps) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (phase != phase_) {
      finish();
      phase_ = phase;
      start_ = now;
    }
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double rate = elapsed > 0 ? steps / elapsed : 0.0;
    std::string eta = "--";
    if (fraction > 0.01 && fraction < 1.0) eta = std::to_string(static_cast<long>(elapsed * (1.0 - fraction) / fraction)) + " s";
    std::fprintf(stderr, "\r\033[K%-34s %5.1f %%  %9ld steps  %8.0f steps/s  ETA %s", phase.c_str(),
                 100.0 * fraction, steps, rate, eta.c_str());
    std::fflush(stderr);
    open_ = true;
  }
  void finish() {
    if (enabled_ && open_) std::fprintf(stderr, "\n");
    open_ = false;
  }

 private:
  bool enabled_;
  bool open_ = false;
  std::string phase_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace grainlab::cli

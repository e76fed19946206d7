#pragma once
// Progress of long phases: phase, percent, steps, steps/s, ETA. On a terminal, one line rewritten in
// place; when stderr is not a terminal (a log file, a batch system, nohup), a plain line every
// GRAINLAB_PROGRESS_SECONDS seconds of a phase (60 by default; 0 prints every update), so long
// work shows progress in logs too. Nothing with --quiet.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/errors.hpp"
#include "io/input_file.hpp"

namespace grainlab::cli {

class ProgressLine {
 public:
  // Seconds between log lines from GRAINLAB_PROGRESS_SECONDS (default 60); an InputError naming the
  // variable, its value and what is allowed when it is not a number in [0, 1e6].
  static double logInterval() {
    const char* text = std::getenv("GRAINLAB_PROGRESS_SECONDS");
    if (!text) return 60.0;
    char* end = nullptr;
    const double v = std::strtod(text, &end);
    if (end == text || *end != '\0' || !std::isfinite(v) || v < 0.0 || v > 1e6) {
      throw InputError("environment error: GRAINLAB_PROGRESS_SECONDS = \"" + io::printable(text) +
                       "\": allowed: seconds between progress lines in a log, a number in [0, 1e6]");
    }
    return v;
  }

  explicit ProgressLine(bool quiet)
      : mode_(quiet ? Mode::Off : (::isatty(STDERR_FILENO) ? Mode::Terminal : Mode::Log)),
        interval_(mode_ == Mode::Log ? logInterval() : 0.0) {}
  ~ProgressLine() { finish(); }

  void update(const std::string& phase, double fraction, long steps) {
    if (mode_ == Mode::Off) return;
    const auto now = std::chrono::steady_clock::now();
    if (phase != phase_) {
      finish();
      phase_ = phase;
      start_ = lastLine_ = now;
    }
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double rate = elapsed > 0 ? steps / elapsed : 0.0;
    std::string eta = "--";
    if (fraction > 0.01 && fraction < 1.0) eta = std::to_string(static_cast<long>(elapsed * (1.0 - fraction) / fraction)) + " s";
    if (mode_ == Mode::Log) {
      if (std::chrono::duration<double>(now - lastLine_).count() < interval_ || fraction >= 1.0) return;
      lastLine_ = now;
      std::fprintf(stderr, "grainlab: progress: %s: %.1f %%, %ld steps, %.0f steps/s, elapsed %.0f s, ETA %s\n",
                   phase.c_str(), 100.0 * fraction, steps, rate, elapsed, eta.c_str());
      std::fflush(stderr);
      return;
    }
    std::fprintf(stderr, "\r\033[K%-34s %5.1f %%  %9ld steps  %8.0f steps/s  ETA %s", phase.c_str(),
                 100.0 * fraction, steps, rate, eta.c_str());
    std::fflush(stderr);
    open_ = true;
  }
  void finish() {
    if (mode_ == Mode::Terminal && open_) std::fprintf(stderr, "\n");
    open_ = false;
  }

 private:
  enum class Mode { Off, Terminal, Log };
  Mode mode_;
  double interval_;
  bool open_ = false;
  std::string phase_;
  std::chrono::steady_clock::time_point start_, lastLine_;
};

}  // namespace grainlab::cli

#pragma once
// The macro-values of the undrained, oedometer and cyclic tests, from their records (and, where a
// value is tracked every step, from the protocol's state). Pure functions of the records, so they
// are tested against hand numbers; null (nullopt) where a value cannot be measured, never 0.
#include <optional>
#include <vector>

#include "lab/protocols.hpp"

namespace grainlab::lab {

struct UndrainedSummary {
  double uMax = 0.0;           // largest excess pore pressure [Pa]
  double uMin = 0.0;           // smallest (most negative) excess pore pressure [Pa]
  double pMin = 0.0;           // smallest mean effective stress [Pa]
  // Deviator where the effective stress path turns from contractive to dilative (the minimum of p'
  // between the first and the last record); null where p' only rises or only falls.
  std::optional<double> qAtPhaseTransformation, eps1AtPhaseTransformation;
  bool liquefied = false;      // p' fell to (1 - ru_limit) p0 or below
  double volumeDriftMax = 0.0; // largest |eps_v| of any step
};
UndrainedSummary undrainedSummary(const std::vector<Record>& records, double p0, double ruLimit, double volumeDriftMax);

struct OedometerSummary {
  // sigma_h / sigma_v on loading, the mean over the loading records with sigma_v at or above the
  // geometric mean of the start and the largest axial stress (the normally loaded part; the start
  // is isotropic, K = 1), and at the end of unloading; null without records there.
  std::optional<double> k0, k0Unloading;
  // Compression and swelling indices -de/dlog10(sigma_v): least-squares slopes over the same
  // loading records, and over every unloading record; null with fewer than 3 records.
  std::optional<double> cc, cs;
  double sigmaVMax = 0.0;      // the largest axial stress reached [Pa]
  std::size_t loadingRecords = 0, unloadingRecords = 0;
};
OedometerSummary oedometerSummary(const std::vector<Record>& records, double p0);

struct CyclicSummary {
  std::optional<double> cyclesToLiquefaction;  // null: did not liquefy within test.n_cycles
  double ruMax = 0.0;                 // largest u/p0 (undrained; 0 drained)
  double cycles = 0.0;                // cycles completed (halves)
  double doubleAmplitudeMax = 0.0;    // largest double-amplitude axial strain of a cycle
};
CyclicSummary cyclicSummary(const ProtocolState& state);

}  // namespace grainlab::lab

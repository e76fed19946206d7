#pragma once
// Error types thrown by library code; the command line maps them to exit codes
// (InputError -> 2, SimulationError -> 1). Library code never calls exit().
#include <stdexcept>
#include <string>

namespace grainlab {

// Bad user input: the message names the key, the value and what is allowed.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A run that failed numerically (NaN, a particle escaping the box, no convergence).
struct SimulationError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A run stopped on request between steps (Ctrl-C in the Python module): handled as a failed run
// whose summary says "interrupted"; the results folder is left as a killed run leaves it.
struct RunInterrupted : SimulationError {
  using SimulationError::SimulationError;
};

}  // namespace grainlab

// The error a run stops with when the physics cannot go on (a step below dt_min, a
// diverged state, a pre-roll that does not settle): exit 1, not a bug.
#pragma once
#include <stdexcept>

namespace shellmpm {

/// Raised when the simulation cannot go on (e.g. the step needed falls below dt_min).
struct SimulationError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace shellmpm

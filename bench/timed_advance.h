// The timed solver advance the solver benchmarks share.
#pragma once
#include <chrono>

#include "sim/solver/solver.h"

namespace shellmpm_bench {

/// What a timed Solver::advance_to returns: its frame statistics and the wall-clock
/// seconds it took.
struct TimedAdvance {
  shellmpm::FrameStats stats;
  double seconds = 0;
};

/// Advances `solver` by `span` seconds of simulated time from its current time, timed.
inline TimedAdvance timed_advance(shellmpm::Solver& solver, double span) {
  const double t0 = solver.time();
  const auto w0 = std::chrono::steady_clock::now();
  TimedAdvance r;
  r.stats = solver.advance_to(t0 + span);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  return r;
}

}  // namespace shellmpm_bench

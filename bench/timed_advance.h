// The timed solver advance the solver benchmarks share.
#pragma once
#include <chrono>
#include <string>

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

/// Whether a FrameStats::stage_seconds entry is work done once per frame (the particles'
/// reorder, the integrity monitor's frame checks, the frame's statistics), not per step.
/// A timed advance is one frame of a few dozen steps where a production frame has
/// hundreds, so the benchmarks count these apart from the per-step figures.
inline bool per_frame_stage(const std::string& name) {
  return name == "reorder" || name == "integrity_frame" || name == "frame_stats";
}

/// Seconds of per-frame work in a timed advance.
inline double per_frame_seconds(const shellmpm::FrameStats& fs) {
  double s = 0;
  for (const auto& [name, v] : fs.stage_seconds)
    if (per_frame_stage(name)) s += v;
  return s;
}

}  // namespace shellmpm_bench

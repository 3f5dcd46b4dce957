// Runs a shot: the frame loop around the solver, with every output the scene asks for
// (density VDBs, particle caches, statistics, checkpoints) and resuming.
// Frame f holds the state at t = (f - 1) / fps: frame 1 is the initial state.
#pragma once
#include <cstdint>
#include <functional>
#include <string>

#include "sim/scene/scene.h"
#include "sim/solver/frame_stats.h"

namespace shellmpm {

struct RunOptions {
  bool resume = false;                 ///< continue from the newest checkpoint in the output dir
  std::uint64_t scene_fingerprint = 0; ///< identifies the scene text for checkpoints
  bool serial = false;                 ///< no threads
  /// After each substep: frame being computed, substep, dt [s], time [s], particle count.
  std::function<void(int, int, double, double, std::size_t)> on_substep;
  /// After each frame is simulated and written.
  std::function<void(const FrameStats&)> on_frame;
  /// Warnings (integrity failures); printed even with --quiet.
  std::function<void(const std::string&)> warn;
  /// Informational messages.
  std::function<void(const std::string&)> log;
};

/// Time of a frame's state [s].
inline double frame_time(int frame, double fps) { return (frame - 1) / fps; }

/// Simulates scene.shot.frame_start..frame_end (simulating from frame 1, or from the
/// checkpoint), writing outputs into scene.output.directory. Returns frames written.
int run_shot(const Scene& scene, const RunOptions& opt);

}  // namespace shellmpm

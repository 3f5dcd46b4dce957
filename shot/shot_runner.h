// Runs a shot: the frame loop around the solver, with every output the scene asks for
// (density VDBs, particle caches, statistics, checkpoints) and resuming.
// Frame f holds the state at t = (f - 1) / fps: frame 1 is the initial state.
#pragma once
#include <cstdint>
#include <functional>
#include <string>

#include "io/frame_number.h"
#include "sim/scene/scene.h"
#include "sim/solver/frame_stats.h"

namespace shellmpm {

struct RunOptions {
  bool resume = false;                  ///< continue from the newest checkpoint in the output dir
  std::uint64_t scene_fingerprint = 0;  ///< identifies the scene text for checkpoints
  bool serial = false;                  ///< no threads
  /// After each substep: frame being computed, substep, dt [s], time [s], particle count.
  std::function<void(int, int, double, double, std::size_t)> on_substep;
  /// After each frame is simulated and written.
  std::function<void(const FrameStats&)> on_frame;
  /// Warnings (integrity failures); printed even with --quiet.
  std::function<void(const std::string&)> warn;
  /// Informational messages.
  std::function<void(const std::string&)> log;
  /// Polled after every substep and frame: a non-zero value (the number of the signal
  /// that asked for it) stops the run once the frame being computed is finished and
  /// written; a checkpoint of that frame is written (whatever output.checkpoint_every
  /// says) so that --resume continues from it.
  std::function<int()> stop_requested;
};

/// What run_shot did.
struct RunResult {
  int frames_written = 0;
  int last_frame = 0;      ///< the last frame simulated (0 if none)
  int stopped_by = 0;      ///< stop_requested's value when the run stopped early, else 0
  std::string checkpoint;  ///< the checkpoint written when it stopped early
};

/// Simulates scene.shot.frame_start..frame_end (simulating from frame 1, or from the
/// checkpoint), writing outputs into scene.output.directory.
///
/// With opt.resume: leftover temporaries of a killed run ("*.tmp.<pid>") are removed
/// from the output folders, and the run continues from the newest intact checkpoint;
/// a damaged newer one is reported through opt.warn, recorded in stats.json under
/// "resume" and skipped. No intact checkpoint among several damaged ones is a UserError;
/// none at all starts from frame 1. A checkpoint of another scene is a UserError.
RunResult run_shot(const Scene& scene, const RunOptions& opt);

}  // namespace shellmpm

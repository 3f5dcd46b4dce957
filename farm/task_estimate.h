// What a task will cost, before it runs (`batch plan`, and the Slurm engine's memory request
// and signal margin): the scene read and checked as `shellmpm check` does it (with the
// task's overrides), its peak memory (shot/run_memory.h) and its time per frame
// (sim/solver/shot_estimate.h) on the threads it will get.
#pragma once
#include <string>

#include "farm/batch_tasks.h"

namespace shellmpm {

struct TaskEstimate {
  double memory_bytes = 0;        ///< estimated peak resident size of the run
  double checkpoint_bytes = 0;    ///< the largest frame writer's transient (an upper bound
                                  ///< on writing a checkpoint)
  double seconds_per_frame = -1;  ///< -1: not estimated (implicit, or too large to build)
  double seconds = -1;            ///< the whole task (frames 1..last simulated), or -1
  std::string warning;            ///< e.g. the stable step is below shot.dt_min
};

/// The estimate of task `t` on `threads` threads (>= 1). `baseline`: resident bytes of a
/// fresh process (resident_bytes() before anything is built).
/// @throws UserError when the scene or an override does not pass the checks of `check`,
///   at the batch file's line for an override (rethrow_for_task).
TaskEstimate estimate_task(const BatchTask& t, int threads, double baseline);

/// The seconds of early warning a farm job needs to finish its frame and write a
/// checkpoint before it is killed (--signal=B:TERM@S): twice a frame, the checkpoint at
/// 50 MB/s, and 60 s for the scheduler's slack (Slurm signals up to 60 s early or late);
/// at least 90, at most 65535.
int signal_margin_seconds(const TaskEstimate& e);

}  // namespace shellmpm

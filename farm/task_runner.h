// One task, as every engine runs it (`shellmpm batch task BATCH INDEX`): it records the
// attempt in the task's status file, runs `shellmpm run` on the task's scene, overrides and
// output folder (resuming from the newest checkpoint there), passes SIGTERM and SIGINT on to
// it (the run finishes its frame, checkpoints and exits 143 or 130), writes the wedge into
// the run's run.json and records the exit. A finished task is skipped. With `preview`, it
// renders the task's caches instead (`shellmpm render`).
#pragma once
#include <string>

#include "farm/batch_tasks.h"

namespace shellmpm {

struct TaskRunOptions {
  int threads = 0;       ///< --threads of the run; 0: all cores
  bool preview = false;  ///< the preview step instead of the simulation
  bool force = false;    ///< run again even when done (from frame 1, not resuming)
  std::string engine;    ///< recorded in the status file ("local", "slurm", ...)
  std::string job;       ///< the scheduler's id of this attempt, if any
};

/// Runs task `index` of the batch. Returns the exit code of the run (0; 1 and 2 for a
/// failed run; 143 or 130 when stopped by a signal, with a checkpoint: run it again to
/// continue), or 0 when it was done already.
/// @throws UserError for an index out of range, or a task folder holding another task's
///   work (a changed scene, overrides or frames).
int run_batch_task(const BatchSpec& b, const std::vector<BatchTask>& tasks, int index,
                   const TaskRunOptions& opt);

/// Adds {"wedge": task_json(t)} to the run.json in the task's folder (when there is one).
void add_wedge_to_manifest(const BatchTask& t);

}  // namespace shellmpm

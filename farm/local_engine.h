// The local engine (`shellmpm batch run`): the batch's tasks on this machine, K at a time
// with the cores split between them, each as its own `shellmpm batch task` process (so a
// crash or a failure stays in its task) logging to the batch's farm folder. It shows a line
// per running task and one for the batch; skips finished tasks; resumes stopped ones from
// their checkpoints; runs a shot's preview step once a task of it is done; passes SIGTERM
// and SIGINT on (every running task checkpoints and exits 143; run again to continue).
#pragma once
#include <vector>

#include "farm/batch_tasks.h"

namespace shellmpm {

struct LocalRunOptions {
  int slots = 0;       ///< tasks at once; 0: the batch file's, else one per core
  int threads = 0;     ///< threads per task; 0: the batch file's, else cores / slots
  bool force = false;  ///< run finished tasks again, from frame 1
  bool quiet = false;  ///< the summary and errors only
};

/// Runs the tasks (frames resolved). Returns 0 when every task is done, 1 when one or more
/// failed (each named with its log's last lines), 143 or 130 when stopped by a signal.
/// @throws UserError before starting anything when a task folder holds another task's work.
int run_local(const BatchSpec& b, const std::vector<BatchTask>& tasks, const LocalRunOptions& o);

}  // namespace shellmpm

// Per-task status files on the shared disk: what `batch task` records before and after
// each attempt (state, attempts, last exit code, wall time, where it ran), so that
// `batch status` and `batch collect` need no scheduler and no Slurm accounting. One JSON
// file per task in the batch's farm folder (status/NNNN.json), written atomically.
#pragma once
#include <optional>
#include <string>

#include "farm/batch_tasks.h"

namespace shellmpm {

/// The task's state as its last attempt left it.
enum class TaskState { Pending, Running, Stopped, Done, Failed };

std::string word_of_state(TaskState s);

/// One step's record (the simulation, or the preview render).
struct StepStatus {
  TaskState state = TaskState::Pending;
  int attempts = 0;
  int last_exit = -1;       ///< -1: none yet
  double wall_seconds = 0;  ///< summed over attempts
  double started = 0;       ///< Unix time of the last attempt's start
  double finished = 0;      ///< Unix time of the last attempt's end (0 while running)
};

struct TaskStatus {
  int index = 0;
  std::string id;           ///< shot/wedge
  std::string fingerprint;  ///< task_fingerprint, hex
  StepStatus sim, preview;
  std::string host;    ///< where the last attempt ran
  int pid = 0;         ///< the `batch task` process of the last attempt, on `host`
  std::string engine;  ///< local, slurm, or what SHELLMPM_FARM_ENGINE says
  std::string job;     ///< the scheduler's id of the last attempt (e.g. 1234_3), if any
  int restarts() const { return sim.attempts > 0 ? sim.attempts - 1 : 0; }
};

/// FARM/status/NNNN.json.
std::string status_path(const BatchSpec& b, int index);

/// FARM/logs/task.NNNN.log (the local engine's; the Slurm job script's --output pattern
/// `task.%4a.log` gives the same names).
std::string log_path(const BatchSpec& b, int index);

/// The status file of task `index`, or nothing when there is none yet.
/// @throws UserError naming the file when it is not a status file.
std::optional<TaskStatus> read_task_status(const BatchSpec& b, int index);

/// Writes it atomically (creating the status folder).
void write_task_status(const BatchSpec& b, const TaskStatus& s);

/// Frames of the task written so far: stats.json's frames from frame_start on (0 when
/// there is no stats.json yet).
int frames_done(const BatchTask& t);

/// "%016llx" of a fingerprint.
std::string hex_fingerprint(std::uint64_t f);

/// Seconds since the Unix epoch, now.
double unix_now();

}  // namespace shellmpm

// `shellmpm batch status`: one table of the batch's tasks from their status files and
// stats.json on the shared disk (state, frames done, restarts, last exit, wall time), plus
// the scheduler's view (squeue) when the batch was submitted to Slurm and squeue answers.
// It never needs Slurm accounting (sacct): small sites run without it.
#pragma once
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "farm/task_status.h"

namespace shellmpm {

struct StatusRow {
  const BatchTask* task = nullptr;
  std::optional<TaskStatus> status;  ///< none: the task has not started
  int frames_done = 0;
  std::string scheduler;  ///< squeue's state and reason ("PENDING (BeginTime)"), or ""
  /// The state shown: the status file's; "pending"/"queued" (the scheduler holds it)
  /// before it starts; "lost" when it says running but its process on this machine is gone
  /// (killed with SIGKILL: the next `batch run` resumes it from its checkpoint).
  std::string state() const;
  bool scheduler_running() const { return scheduler.rfind("RUNNING", 0) == 0; }
};

/// squeue's view of a submitted batch: task index -> "STATE (REASON)", read from
/// FARM/slurm/submit.json's job ids. Empty when the batch was not submitted to Slurm or
/// squeue is missing or fails (`note` says which).
std::map<int, std::string> squeue_view(const BatchSpec& b, std::string* note);

std::vector<StatusRow> status_rows(const BatchSpec& b, const std::vector<BatchTask>& tasks,
                                   const std::map<int, std::string>& scheduler);

/// The table as text, a header line and one line per task, then a summary line.
std::string status_table(const BatchSpec& b, const std::vector<StatusRow>& rows);

/// The same as JSON: {"batch", "tasks": [{index, id, state, frames_done, frames, restarts,
/// last_exit, wall_seconds, preview, host, job, scheduler, log}]}.
nlohmann::json status_json(const BatchSpec& b, const std::vector<StatusRow>& rows);

}  // namespace shellmpm

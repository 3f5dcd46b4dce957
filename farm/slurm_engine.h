// The Slurm engine (`shellmpm batch submit --engine slurm`): one job array for the batch's
// tasks and, when a shot has a preview step, a second array of preview tasks that waits for
// the first (afterok, killed if that can never be met). Each array task runs
// `shellmpm batch task BATCH $SLURM_ARRAY_TASK_ID`, which resumes from the task's newest
// checkpoint; the job script forwards the early --signal to it and, when the run stopped
// with a checkpoint (exit 143), requeues its own array task. Scripts, the task table and
// the submission record go to the batch's farm folder (FARM/slurm/).
#pragma once
#include <string>
#include <vector>

#include "farm/batch_tasks.h"

namespace shellmpm {

struct SlurmSubmit {
  SlurmSettings settings;  ///< the batch file's, with the flags applied over them
  bool dry_run = false;    ///< write and print, submit nothing
  std::string shellmpm;    ///< the binary the jobs run (absolute); default: this one
  int signal_seconds = 0;  ///< S of --signal=B:TERM@S (resolved)
  std::string mem;         ///< --mem (resolved; empty: none)
};

/// The job scripts of a submission.
struct SlurmScripts {
  std::string job;            ///< the task array
  std::string preview;        ///< the preview array ("" when no shot has a preview)
  std::string array;          ///< "0-7%2"
  std::string preview_array;  ///< "0-3,6" ("" when none)
};

/// The scripts for `tasks` (pure: no files, no commands).
SlurmScripts slurm_scripts(const BatchSpec& b, const std::vector<BatchTask>& tasks,
                           const SlurmSubmit& s);

/// Checks, before anything is written, that Slurm can take the batch: sbatch and scontrol on
/// PATH, the controller answering (scontrol ping), the partitions existing (sinfo).
/// @throws UserError saying which, with what the command printed.
void slurm_preflight(const SlurmSettings& s);

/// Writes FARM/slurm/job.sh (and preview.sh), the task table, and (unless dry_run)
/// submits them with sbatch, recording the job ids in FARM/slurm/submit.json. Prints what it
/// did (the scripts and the sbatch commands with --dry-run). Returns the exit code.
int submit_slurm(const BatchSpec& b, const std::vector<BatchTask>& tasks, const SlurmSubmit& s);

/// The array spec for task indices: runs joined ("0-3,6,8-9"), with "%K" when throttle > 0.
std::string array_spec(const std::vector<int>& indices, int throttle);

}  // namespace shellmpm

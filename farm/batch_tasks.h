// A batch expanded into numbered tasks: one per shot and wedge member, in a fixed order
// (shots in file order, each shot's wedge members in the wedge's order), each writing to
// a folder that depends only on its names: OUTPUT/<shot>/<wedge member>/. Every engine runs
// task i as `shellmpm batch task BATCH i`; the task table (tasks.json in the batch's farm
// folder) records the expansion for status, collect and the schedulers.
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "farm/batch_file.h"
#include "io/user_error.h"

namespace shellmpm {

struct BatchTask {
  int index = 0;
  std::string shot;
  std::string wedge;                   ///< the wedge member's name, or "base"
  std::vector<Override> wedge_values;  ///< what the wedge member sets (empty for "base")
  std::vector<Override> overrides;     ///< the shot's `set`, then the wedge member's
  std::string scene;                   ///< absolute path
  int frame_start = 0, frame_end = 0;  ///< the frames written; 0: not yet resolved
  bool frames_from_batch = false;      ///< the batch states them (run gets --frames)
  std::string output;                  ///< absolute: BATCH_OUTPUT/<shot>/<wedge>
  PreviewSpec preview;
  std::string id() const { return shot + "/" + wedge; }
};

/// The batch's tasks, numbered from 0. Frames are the batch's, or 0 until resolve_frames.
std::vector<BatchTask> expand_tasks(const BatchSpec& b);

/// Reads every task's scene with its overrides (as `run` will) and fills in the frames the
/// scene states where the batch does not. A bad override is reported at its line in the
/// batch file ("batch.yaml:12: shots[0].set.shot.dxx: ..."), any other scene error as the
/// scene reader reports it, prefixed with the task.
/// @throws UserError
void resolve_frames(std::vector<BatchTask>& tasks);

/// Rethrows a UserError of reading `t`'s scene at the batch file line of the override it
/// came from, when it came from one; else with the task named. Never returns.
[[noreturn]] void rethrow_for_task(const UserError& e, const BatchTask& t);

/// The arguments of `shellmpm run` for the task (after "run"): scene, --frames, --output,
/// --set for each override. Threads and --resume are the caller's.
std::vector<std::string> run_arguments(const BatchTask& t);

/// A hash of what decides the task's caches: the scene file's text, the overrides and the
/// frames. A task folder holding another one's work is refused rather than mixed.
std::uint64_t task_fingerprint(const BatchTask& t);

/// The batch's own folder for tables, status files, logs and job scripts: OUTPUT/_farm.
std::string farm_dir(const BatchSpec& b);

/// The task as JSON (the task table's row; also what run.json's "wedge" block holds).
nlohmann::json task_json(const BatchTask& t);

/// The task table: {"batch", "output", "tasks": [...]}.
nlohmann::json task_table_json(const BatchSpec& b, const std::vector<BatchTask>& tasks);

/// Writes tasks.json and tasks.tsv (index, shot, wedge, values, frames, output) into the
/// farm folder, creating it.
void write_task_table(const BatchSpec& b, const std::vector<BatchTask>& tasks);

/// "friction=0.1 youngs_modulus=2e4" (the wedge member's values), or "-".
std::string values_text(const BatchTask& t);

}  // namespace shellmpm

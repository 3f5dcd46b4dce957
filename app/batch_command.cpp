#include "app/batch_command.h"

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "app/commands.h"
#include "farm/batch_status.h"
#include "farm/local_engine.h"
#include "farm/review_page.h"
#include "farm/slurm_engine.h"
#include "farm/subprocess.h"
#include "farm/task_estimate.h"
#include "farm/task_runner.h"
#include "farm/wedge_table.h"
#include "io/atomic_file.h"
#include "io/user_error.h"
#include "shot/available_memory.h"

namespace shellmpm {
namespace {

namespace fs = std::filesystem;

/// The batch and its tasks with their frames (every scene read with its overrides).
struct LoadedBatch {
  BatchSpec spec;
  std::vector<BatchTask> tasks;
};

LoadedBatch load_batch(const std::string& path) {
  LoadedBatch lb;
  lb.spec = read_batch_file(path);
  lb.tasks = expand_tasks(lb.spec);
  resolve_frames(lb.tasks);
  return lb;
}

std::string seconds_text(double s) {
  if (s < 0) return "?";
  char buf[64];
  if (s < 120)
    std::snprintf(buf, sizeof buf, "%.1f s", s);
  else if (s < 7200)
    std::snprintf(buf, sizeof buf, "%.1f min", s / 60);
  else
    std::snprintf(buf, sizeof buf, "%.1f h", s / 3600);
  return buf;
}

/// Slots and threads per task as the local engine would pick them for `n` tasks.
std::pair<int, int> local_split(const BatchArgs& a, const BatchSpec& b, int n) {
  const int cores = available_cores();
  int slots = a.slots > 0 ? a.slots : b.farm.slots > 0 ? b.farm.slots : cores;
  slots = std::max(1, std::min(slots, n));
  const int threads = a.threads > 0        ? a.threads
                      : b.farm.threads > 0 ? b.farm.threads
                                           : std::max(1, cores / slots);
  return {slots, threads};
}

/// Every task's estimate; a task that does not pass `check` is printed and the batch
/// refused (exit 2) once all are checked.
std::vector<TaskEstimate> estimate_all(const LoadedBatch& lb, int threads) {
  const double baseline = resident_bytes();
  std::vector<TaskEstimate> est;
  std::vector<std::string> errors;
  for (const BatchTask& t : lb.tasks) {
    try {
      est.push_back(estimate_task(t, threads, baseline));
    } catch (const UserError& e) {
      errors.push_back(e.what());
      est.emplace_back();
    }
  }
  if (errors.empty()) return est;
  for (std::size_t i = 0; i + 1 < errors.size(); ++i)
    std::fprintf(stderr, "error: %s\n", errors[i].c_str());
  throw UserError(
      lb.spec.path, 0, "",
      std::to_string(errors.size()) + " of " + std::to_string(lb.tasks.size()) +
          " tasks do not pass `check`; nothing was run or written. The last: " + errors.back());
}

int plan(const BatchArgs& a) {
  const LoadedBatch lb = load_batch(a.batch);
  const auto [slots, threads] = local_split(a, lb.spec, static_cast<int>(lb.tasks.size()));
  const std::vector<TaskEstimate> est = estimate_all(lb, threads);
  if (a.json) {
    nlohmann::json j = task_table_json(lb.spec, lb.tasks);
    for (std::size_t i = 0; i < est.size(); ++i) {
      j["tasks"][i]["memory_bytes"] = est[i].memory_bytes;
      j["tasks"][i]["seconds_per_frame"] = est[i].seconds_per_frame;
      j["tasks"][i]["seconds"] = est[i].seconds;
    }
    std::printf("%s\n", j.dump(2).c_str());
    return kExitOk;
  }
  std::printf("batch %s (%s): %zu tasks into %s\n", lb.spec.name.c_str(), lb.spec.path.c_str(),
              lb.tasks.size(), lb.spec.output.c_str());
  std::printf("%-5s %-34s %-40s %-9s %-10s %-9s %-9s %s\n", "task", "shot/wedge", "values",
              "frames", "memory", "s/frame", "total", "preview");
  double total = 0, peak = 0;
  for (std::size_t i = 0; i < lb.tasks.size(); ++i) {
    const BatchTask& t = lb.tasks[i];
    const std::string frames = std::to_string(t.frame_start) + "-" + std::to_string(t.frame_end);
    char spf[32];
    std::snprintf(spf, sizeof spf, "%.3g", est[i].seconds_per_frame);
    std::printf("%-5d %-34s %-40s %-9s %-10s %-9s %-9s %s\n", t.index, t.id().c_str(),
                values_text(t).c_str(), frames.c_str(), format_bytes(est[i].memory_bytes).c_str(),
                est[i].seconds_per_frame < 0 ? "?" : spf, seconds_text(est[i].seconds).c_str(),
                t.preview.enabled ? "yes" : "-");
    if (!est[i].warning.empty()) std::printf("      warning: %s\n", est[i].warning.c_str());
    total += std::max(0.0, est[i].seconds);
    peak = std::max(peak, est[i].memory_bytes);
  }
  std::printf(
      "here: %d at a time, %d thread%s each: about %s (simulation only), up to %s at once\n", slots,
      threads, threads == 1 ? "" : "s", seconds_text(total / slots).c_str(),
      format_bytes(peak * slots).c_str());
  return kExitOk;
}

int run(const BatchArgs& a) {
  const LoadedBatch lb = load_batch(a.batch);
  LocalRunOptions o;
  o.slots = a.slots;
  o.threads = a.threads;
  o.force = a.force;
  o.quiet = a.quiet;
  return run_local(lb.spec, lb.tasks, o);
}

int submit(const BatchArgs& a) {
  if (a.engine != "slurm")
    throw UserError("--engine", 0, "",
                    "unknown engine '" + a.engine +
                        "': `batch submit` knows slurm; `batch run` is the local engine; "
                        "Deadline, OpenCue and Tractor call `batch task` (docs/farm.md)");
  const LoadedBatch lb = load_batch(a.batch);
  SlurmSubmit s;
  s.settings = lb.spec.farm.slurm;
  SlurmSettings& r = s.settings;
  if (!a.partition.empty()) r.partition = a.partition;
  if (!a.time.empty()) r.time = a.time;
  if (!a.mem.empty()) r.mem = a.mem;
  if (!a.account.empty()) r.account = a.account;
  if (!a.qos.empty()) r.qos = a.qos;
  if (a.cpus > 0) r.cpus = a.cpus;
  if (a.throttle > 0) r.throttle = a.throttle;
  if (a.signal_seconds > 0) r.signal_seconds = a.signal_seconds;
  s.dry_run = a.dry_run;
  s.shellmpm = a.shellmpm.empty() ? self_executable() : fs::absolute(a.shellmpm).string();
  // Memory and signal margin from the estimates (which also refuse scenes that fail check).
  const std::vector<TaskEstimate> est = estimate_all(lb, r.cpus > 0 ? r.cpus : 1);
  TaskEstimate worst;
  for (const TaskEstimate& e : est) {
    worst.memory_bytes = std::max(worst.memory_bytes, e.memory_bytes);
    worst.checkpoint_bytes = std::max(worst.checkpoint_bytes, e.checkpoint_bytes);
    worst.seconds_per_frame = std::max(worst.seconds_per_frame, e.seconds_per_frame);
  }
  s.signal_seconds = r.signal_seconds > 0 ? r.signal_seconds : signal_margin_seconds(worst);
  s.mem = !r.mem.empty() ? r.mem
                         : std::to_string(static_cast<long long>(
                               std::ceil(worst.memory_bytes * 1.25 / (1024.0 * 1024.0)))) +
                               "M";
  return submit_slurm(lb.spec, lb.tasks, s);
}

int status(const BatchArgs& a) {
  const LoadedBatch lb = load_batch(a.batch);
  std::string note;
  const std::map<int, std::string> view = squeue_view(lb.spec, &note);
  const std::vector<StatusRow> rows = status_rows(lb.spec, lb.tasks, view);
  if (a.json) {
    std::printf("%s\n", status_json(lb.spec, rows).dump(2).c_str());
    return kExitOk;
  }
  std::printf("%s", status_table(lb.spec, rows).c_str());
  if (!note.empty()) std::printf("%s\n", note.c_str());
  return kExitOk;
}

int collect(const BatchArgs& a) {
  const LoadedBatch lb = load_batch(a.batch);
  const WedgeTable table = build_wedge_table(lb.spec, lb.tasks);
  const std::string dir = a.output.empty() ? lb.spec.output : a.output;
  fs::create_directories(dir);
  write_text_atomic(dir + "/wedge_table.csv", wedge_csv(table));
  write_text_atomic(dir + "/wedge_table.md", wedge_markdown(table));
  write_text_atomic(dir + "/wedge_table.json", wedge_json(lb.spec, table).dump(2) + "\n");
  write_text_atomic(dir + "/review.html", review_page_html(lb.spec, table));
  if (!a.quiet) std::printf("%s", wedge_markdown(table).c_str());
  std::printf("wrote %s/wedge_table.csv, wedge_table.md, wedge_table.json and review.html\n",
              dir.c_str());
  int unfinished = 0;
  for (const WedgeRow& r : table.rows) unfinished += r.state != "done";
  if (unfinished > 0)
    std::printf("note: %d of %zu tasks are not done (`shellmpm batch status`)\n", unfinished,
                table.rows.size());
  return kExitOk;
}

int task(const BatchArgs& a) {
  const LoadedBatch lb = load_batch(a.batch);
  TaskRunOptions o;
  o.threads = a.threads > 0 ? a.threads : lb.spec.farm.threads;
  o.preview = a.preview;
  o.force = a.force;
  const char* engine = std::getenv("SHELLMPM_FARM_ENGINE");
  o.engine = !a.task_engine.empty() ? a.task_engine : engine ? engine : "direct";
  o.job = a.job;
  return run_batch_task(lb.spec, lb.tasks, a.index, o);
}

}  // namespace

CLI::App* add_batch_subcommand(CLI::App& app, BatchArgs& a) {
  CLI::App* batch =
      app.add_subcommand("batch", "batches of shots and wedges, here or on a farm (docs/farm.md)");
  batch->require_subcommand(1);
  auto add = [&](const char* name, const char* help) {
    CLI::App* c = batch->add_subcommand(name, help);
    c->add_option("BATCH", a.batch, "batch file (YAML)")->required();
    return c;
  };
  CLI::App* plan_cmd = add("plan",
                           "print the task table with memory and time estimates; refuse "
                           "a batch whose scenes do not pass `check`");
  plan_cmd->add_flag("--json", a.json, "the table as JSON");
  CLI::App* run_cmd = add("run", "run the tasks here (the local engine), K at a time");
  for (CLI::App* c : {plan_cmd, run_cmd}) {
    c->add_option("--slots,-k", a.slots, "tasks at once (default: farm.slots, else the cores)")
        ->check(CLI::PositiveNumber);
    c->add_option("--threads", a.threads, "threads per task (default: the cores / slots)")
        ->check(CLI::PositiveNumber);
  }
  run_cmd->add_flag("--force", a.force, "run finished tasks again from frame 1");
  run_cmd->add_flag("--quiet,-q", a.quiet, "the summary and errors only");
  CLI::App* sub = add("submit", "submit the batch to a farm scheduler as one job array");
  sub->add_option("--engine", a.engine, "slurm");
  sub->add_flag("--dry-run", a.dry_run, "write and print the job scripts, submit nothing");
  sub->add_option("--partition,-p", a.partition, "partition (default: farm.slurm.partition)");
  sub->add_option("--time,-t", a.time, "time limit per task, e.g. 02:00:00");
  sub->add_option("--mem", a.mem, "memory per task, e.g. 4G (default: the estimate + 25%)");
  sub->add_option("--cpus", a.cpus, "cpus per task (= threads)")->check(CLI::PositiveNumber);
  sub->add_option("--throttle", a.throttle, "at most K tasks at once (--array=...%K)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--signal-seconds", a.signal_seconds,
                  "S of --signal=B:TERM@S (default: from the frame time and checkpoint size)")
      ->check(CLI::Range(1, 65535));
  sub->add_option("--account", a.account, "account");
  sub->add_option("--qos", a.qos, "quality of service");
  sub->add_option("--shellmpm", a.shellmpm, "the shellmpm binary the nodes run (default: this)");
  CLI::App* st = add("status", "the tasks' states from their status files (+ squeue)");
  st->add_flag("--json", a.json, "the table as JSON");
  CLI::App* col = add("collect", "the wedge table (CSV, JSON, Markdown) and review.html");
  col->add_option("--output,-o", a.output, "folder to write them to (default: the batch output)");
  col->add_flag("--quiet,-q", a.quiet, "do not print the table");
  CLI::App* tk = add("task", "run one task (what every engine runs)");
  tk->add_option("INDEX", a.index, "task index (see `batch plan`)")->required();
  tk->add_option("--threads", a.threads, "threads (default: farm.threads, else all cores)")
      ->check(CLI::NonNegativeNumber);
  tk->add_flag("--preview", a.preview, "run the task's preview step (render) instead");
  tk->add_flag("--force", a.force, "run it again from frame 1 even when done");
  tk->add_option("--engine", a.task_engine, "the engine's name, recorded in the status file");
  tk->add_option("--job", a.job, "the scheduler's id of this attempt, recorded");
  return batch;
}

int batch_command(CLI::App& batch, const BatchArgs& a) {
  const std::string which = batch.get_subcommands().front()->get_name();
  if (which == "plan") return plan(a);
  if (which == "run") return run(a);
  if (which == "submit") return submit(a);
  if (which == "status") return status(a);
  if (which == "collect") return collect(a);
  return task(a);
}

}  // namespace shellmpm

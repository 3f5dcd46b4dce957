#include "farm/batch_status.h"

#include <signal.h>

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "farm/subprocess.h"

namespace shellmpm {
namespace {

std::string fixed(double x, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, x);
  return buf;
}

/// "123_4" -> 4 when 123 is `job`; -1 otherwise.
int array_index(const std::string& id, const std::string& job) {
  if (id.rfind(job + "_", 0) != 0) return -1;
  const std::string rest = id.substr(job.size() + 1);
  if (rest.empty() || rest.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stoi(rest);
}

}  // namespace

std::string StatusRow::state() const {
  if (status && status->sim.state == TaskState::Running && !scheduler_running() &&
      status->host == short_hostname() && status->pid > 0 && kill(status->pid, 0) != 0 &&
      errno == ESRCH)
    return "lost";  // its process on this machine is gone (killed hard): run it again
  if (status) return word_of_state(status->sim.state);
  return scheduler.empty() ? "pending" : "queued";
}

namespace {

/// squeue's lines for job `job` (one per array task), "STATE (REASON)" by task index,
/// prefixed with `prefix`, merged into `view`. False when squeue fails.
bool add_squeue(const std::string& job, const std::string& prefix, std::map<int, std::string>& view,
                std::string* note) {
  // -r: one line per array task, pending ones too.
  const CommandOutput q = run_capture({"squeue", "-h", "-r", "-j", job, "-o", "%i|%T|%r"}, 20);
  if (q.code != 0) {
    if (note) *note = "squeue failed (" + q.output.substr(0, q.output.find('\n')) + ")";
    return false;
  }
  std::istringstream lines(q.output);
  std::string line;
  while (std::getline(lines, line)) {
    const std::size_t a = line.find('|'), c = line.rfind('|');
    if (a == std::string::npos || c == a) continue;
    const int index = array_index(line.substr(0, a), job);
    if (index < 0) continue;
    const std::string reason = line.substr(c + 1);
    std::string& v = view[index];
    v += (v.empty() ? "" : "; ") + prefix + line.substr(a + 1, c - a - 1) +
         (reason == "None" ? "" : " (" + reason + ")");
  }
  return true;
}

}  // namespace

std::map<int, std::string> squeue_view(const BatchSpec& b, std::string* note) {
  std::map<int, std::string> view;
  std::ifstream in(farm_dir(b) + "/slurm/submit.json", std::ios::binary);
  if (!in) return view;
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, false);
  if (j.is_discarded() || !j.contains("array_job")) return view;
  const std::string job = j["array_job"].get<std::string>();
  if (find_program("squeue").empty()) {
    if (note) *note = "squeue is not on PATH: the scheduler's view is left out";
    return view;
  }
  if (!add_squeue(job, "", view, note)) return view;
  std::string jobs = "array job " + job;
  if (j.contains("preview_job")) {
    const std::string pv = j["preview_job"].get<std::string>();
    if (!add_squeue(pv, "preview ", view, note)) return view;
    jobs += ", preview array " + pv;
  }
  if (note) *note = "scheduler: squeue, " + jobs;
  return view;
}

std::vector<StatusRow> status_rows(const BatchSpec& b, const std::vector<BatchTask>& tasks,
                                   const std::map<int, std::string>& scheduler) {
  std::vector<StatusRow> rows;
  for (const BatchTask& t : tasks) {
    StatusRow r;
    r.task = &t;
    r.status = read_task_status(b, t.index);
    r.frames_done = frames_done(t);
    if (auto it = scheduler.find(t.index); it != scheduler.end()) r.scheduler = it->second;
    rows.push_back(r);
  }
  return rows;
}

std::string status_table(const BatchSpec& b, const std::vector<StatusRow>& rows) {
  char line[1024];
  std::string s;
  std::snprintf(line, sizeof line, "%-5s %-36s %-8s %-9s %-8s %-9s %-9s %-8s %s\n", "task",
                "shot/wedge", "state", "frames", "restarts", "last exit", "wall", "preview",
                "scheduler");
  s += line;
  std::map<std::string, int> counts;
  for (const StatusRow& r : rows) {
    const BatchTask& t = *r.task;
    const std::string frames =
        std::to_string(r.frames_done) + "/" + std::to_string(t.frame_end - t.frame_start + 1);
    std::string exit = "-", wall = "-", restarts = "0",
                preview = t.preview.enabled ? "pending" : "-";
    if (r.status) {
      if (r.status->sim.last_exit >= 0) exit = std::to_string(r.status->sim.last_exit);
      wall = fixed(r.status->sim.wall_seconds, 1) + " s";
      restarts = std::to_string(r.status->restarts());
      if (t.preview.enabled) preview = word_of_state(r.status->preview.state);
    }
    const std::string state = r.state();
    ++counts[state];
    std::snprintf(line, sizeof line, "%-5d %-36s %-8s %-9s %-8s %-9s %-9s %-8s %s\n", t.index,
                  t.id().c_str(), state.c_str(), frames.c_str(), restarts.c_str(), exit.c_str(),
                  wall.c_str(), preview.c_str(), r.scheduler.empty() ? "-" : r.scheduler.c_str());
    s += line;
  }
  for (const StatusRow& r : rows)
    if (r.state() == "failed" || r.state() == "lost")
      s += "task " + std::to_string(r.task->index) + " " + r.state() + ": see " +
           log_path(b, r.task->index) + "\n";
  s += "batch " + b.name + ": " + std::to_string(rows.size()) + " tasks";
  for (const auto& [state, n] : counts) s += ", " + std::to_string(n) + " " + state;
  return s + "\n";
}

nlohmann::json status_json(const BatchSpec& b, const std::vector<StatusRow>& rows) {
  nlohmann::json j;
  j["batch"] = b.path;
  j["tasks"] = nlohmann::json::array();
  for (const StatusRow& r : rows) {
    const BatchTask& t = *r.task;
    nlohmann::json e;
    e["index"] = t.index;
    e["id"] = t.id();
    e["state"] = r.state();
    e["frames_done"] = r.frames_done;
    e["frames"] = t.frame_end - t.frame_start + 1;
    e["restarts"] = r.status ? r.status->restarts() : 0;
    e["last_exit"] = r.status ? r.status->sim.last_exit : -1;
    e["wall_seconds"] = r.status ? r.status->sim.wall_seconds : 0.0;
    e["preview"] = !t.preview.enabled ? "-"
                   : r.status         ? word_of_state(r.status->preview.state)
                                      : "pending";
    e["host"] = r.status ? r.status->host : "";
    e["job"] = r.status ? r.status->job : "";
    e["scheduler"] = r.scheduler;
    e["log"] = log_path(b, t.index);
    j["tasks"].push_back(e);
  }
  return j;
}

}  // namespace shellmpm

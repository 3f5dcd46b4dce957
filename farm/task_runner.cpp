#include "farm/task_runner.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "farm/signal_relay.h"
#include "farm/subprocess.h"
#include "farm/task_status.h"
#include "io/atomic_file.h"
#include "io/user_error.h"

namespace shellmpm {
namespace {

namespace fs = std::filesystem;

std::string clock_text(double unix_seconds) {
  const std::time_t t = static_cast<std::time_t>(unix_seconds);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", std::localtime(&t));
  return buf;
}

std::string joined(const std::vector<std::string>& args) {
  std::string s;
  for (const std::string& a : args) {
    const bool quote = a.find_first_of(" \t'\"[]{}$") != std::string::npos;
    s += (s.empty() ? "" : " ") + (quote ? "'" + a + "'" : a);
  }
  return s;
}

/// The task's status, new or as the last attempt left it; a folder holding another task's
/// work (another fingerprint) is refused.
TaskStatus load_status(const BatchSpec& b, const BatchTask& t) {
  const std::string fp = hex_fingerprint(task_fingerprint(t));
  std::optional<TaskStatus> s = read_task_status(b, t.index);
  if (!s) {
    TaskStatus n;
    n.index = t.index;
    n.id = t.id();
    n.fingerprint = fp;
    return n;
  }
  if (s->fingerprint != fp || s->id != t.id())
    throw UserError(b.path, 0, "",
                    "task " + std::to_string(t.index) + " (" + t.id() +
                        ") has changed since it ran as " + s->id +
                        " (its scene file, overrides "
                        "or frames differ; " +
                        status_path(b, t.index) + "): its folder " + t.output +
                        " holds the old task's caches and checkpoints. Remove that "
                        "folder and the status file to run it anew, or give the changed task "
                        "another name");
  return *s;
}

/// An exclusive lock on FARM/status/NNNN.lock for as long as it lives: two attempts of one
/// task never run at once (a requeued attempt starting while the last one still writes its
/// checkpoint waits for it, up to `wait_s`).
class TaskLock {
 public:
  TaskLock(const BatchSpec& b, int index, double wait_s) {
    const std::string path =
        status_path(b, index).substr(0, status_path(b, index).size() - 5) + ".lock";
    fs::create_directories(fs::path(path).parent_path());
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw UserError(path, 0, "", "cannot open the task's lock file");
    const double end = unix_now() + wait_s;
    while (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      if (unix_now() > end)
        throw UserError(path, 0, "",
                        "task " + std::to_string(index) +
                            " is being run by another process "
                            "(it holds this lock); not starting a second attempt");
      usleep(200000);
    }
  }
  ~TaskLock() {
    if (fd_ >= 0) ::close(fd_);
  }
  TaskLock(const TaskLock&) = delete;
  TaskLock& operator=(const TaskLock&) = delete;

 private:
  int fd_ = -1;
};

/// Runs argv as this task's step, relaying signals; returns its exit code.
int run_step(const std::vector<std::string>& argv, SignalRelay& relay) {
  if (SignalRelay::pending() != 0) return 128 + SignalRelay::pending();
  // In this process's group: whatever kills the task's process tree reaches the run too.
  const pid_t pid = spawn_process(argv, "", false);
  relay.add(pid);
  const int code = wait_process(pid, false);
  relay.remove(pid);
  return code;
}

TaskState state_after(int code) {
  if (code == 0) return TaskState::Done;
  if (code == 143 || code == 130) return TaskState::Stopped;
  return TaskState::Failed;
}

std::string exit_meaning(int code) {
  switch (code) {
    case 0:
      return "done";
    case 1:
      return "failed: the simulation could not go on, or an I/O error (see above)";
    case 2:
      return "failed: bad input (see the message above)";
    case 3:
      return "failed: an internal error in shellmpm";
    case 130:
    case 143:
      return "stopped by a signal with a checkpoint: running the task again continues it";
    default:
      return code > 128 ? "killed by signal " + std::to_string(code - 128) : "failed";
  }
}

int preview_step(const BatchSpec& b, const BatchTask& t, TaskStatus& st, const TaskRunOptions& o,
                 SignalRelay& relay) {
  if (st.sim.state != TaskState::Done)
    throw UserError(b.path, 0, "",
                    "task " + std::to_string(t.index) + " (" + t.id() +
                        "): its simulation is not done (" + word_of_state(st.sim.state) +
                        "), so there is nothing to preview yet");
  std::vector<std::string> argv = {self_executable(), "render", t.output, "--threads",
                                   std::to_string(o.threads)};
  if (!t.preview.size.empty()) argv.insert(argv.end(), {"--size", t.preview.size});
  if (!t.preview.camera.empty()) argv.insert(argv.end(), {"--camera", t.preview.camera});
  if (!t.preview.renderer.empty()) argv.insert(argv.end(), {"--renderer", t.preview.renderer});
  const double start = unix_now();
  st.preview.state = TaskState::Running;
  st.preview.attempts += 1;
  st.preview.started = start;
  st.preview.finished = 0;
  write_task_status(b, st);
  std::printf("== task %d (%s) preview, attempt %d on %s at %s: %s\n", t.index, t.id().c_str(),
              st.preview.attempts, st.host.c_str(), clock_text(start).c_str(),
              joined(argv).c_str());
  std::fflush(stdout);
  const int code = run_step(argv, relay);
  st.preview.last_exit = code;
  st.preview.state = state_after(code);
  st.preview.finished = unix_now();
  st.preview.wall_seconds += st.preview.finished - start;
  write_task_status(b, st);
  std::printf("== task %d (%s) preview: exit %d (%s)\n", t.index, t.id().c_str(), code,
              exit_meaning(code).c_str());
  return code;
}

}  // namespace

void add_wedge_to_manifest(const BatchTask& t) {
  const std::string path = t.output + "/run.json";
  std::ifstream in(path, std::ios::binary);
  if (!in) return;
  std::stringstream text;
  text << in.rdbuf();
  nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) return;
  j["wedge"] = task_json(t);
  write_text_atomic(path, j.dump(2) + "\n");
}

int run_batch_task(const BatchSpec& b, const std::vector<BatchTask>& tasks, int index,
                   const TaskRunOptions& o) {
  if (index < 0 || index >= static_cast<int>(tasks.size()))
    throw UserError(b.path, 0, "",
                    "no task " + std::to_string(index) + ": the batch has " +
                        std::to_string(tasks.size()) + " (0-" + std::to_string(tasks.size() - 1) +
                        ")");
  const BatchTask& t = tasks[index];
  // From the start: a stop before the run starts is one too.
  SignalRelay relay(SignalRelay::Mode::FirstSwapped);
  const TaskLock lock(b, index, 120);
  TaskStatus st = load_status(b, t);
  st.host = short_hostname();
  st.pid = static_cast<int>(getpid());
  st.engine = o.engine;
  st.job = o.job;
  if (o.preview) return preview_step(b, t, st, o, relay);
  if (st.sim.state == TaskState::Done && !o.force) {
    std::printf("== task %d (%s): already done (%d frames in %s); skipping\n", t.index,
                t.id().c_str(), frames_done(t), t.output.c_str());
    return 0;
  }
  std::vector<std::string> argv = {self_executable(), "run"};
  const std::vector<std::string> args = run_arguments(t);
  argv.insert(argv.end(), args.begin(), args.end());
  argv.insert(argv.end(), {"--threads", std::to_string(o.threads)});
  if (!o.force) argv.push_back("--resume");
  const double start = unix_now();
  st.sim.state = TaskState::Running;
  st.sim.attempts += 1;
  st.sim.started = start;
  st.sim.finished = 0;
  write_task_status(b, st);
  std::printf("== task %d (%s) attempt %d on %s (%s%s%s) at %s: %s\n", t.index, t.id().c_str(),
              st.sim.attempts, st.host.c_str(), o.engine.c_str(), o.job.empty() ? "" : " ",
              o.job.c_str(), clock_text(start).c_str(), joined(argv).c_str());
  std::fflush(stdout);
  const int code = run_step(argv, relay);
  add_wedge_to_manifest(t);
  st.sim.last_exit = code;
  st.sim.state = state_after(code);
  st.sim.finished = unix_now();
  st.sim.wall_seconds += st.sim.finished - start;
  write_task_status(b, st);
  std::printf("== task %d (%s): exit %d after %.1f s, %d frames written (%s)\n", t.index,
              t.id().c_str(), code, st.sim.finished - start, frames_done(t),
              exit_meaning(code).c_str());
  std::fflush(stdout);
  return code;
}

}  // namespace shellmpm

#include "farm/local_engine.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <fstream>
#include <thread>

#include "farm/signal_relay.h"
#include "farm/subprocess.h"
#include "farm/task_status.h"
#include "io/checkpoint.h"
#include "io/user_error.h"

namespace shellmpm {
namespace {

struct Job {
  int index = 0;
  bool preview = false;
  pid_t pid = -1;
  double start = 0;
  int frames = -1;  ///< frames written when last shown
};

/// The last `n` lines of a log.
std::string log_tail(const std::string& path, int n) {
  std::ifstream in(path, std::ios::binary);
  std::deque<std::string> lines;
  std::string line;
  while (std::getline(in, line)) {
    lines.push_back(line);
    if (static_cast<int>(lines.size()) > n) lines.pop_front();
  }
  std::string s;
  for (const std::string& l : lines) s += "    | " + l + "\n";
  return s;
}

class LocalEngine {
 public:
  LocalEngine(const BatchSpec& b, const std::vector<BatchTask>& tasks, const LocalRunOptions& o)
      : b_(b), tasks_(tasks), o_(o), tty_(isatty(1) != 0 && !o.quiet) {}
  ~LocalEngine() {
    if (lock_fd_ >= 0) ::close(lock_fd_);
  }
  LocalEngine(const LocalEngine&) = delete;
  LocalEngine& operator=(const LocalEngine&) = delete;

  int run();

 private:
  void plan_jobs();
  void start(Job j);
  void poll(SignalRelay& relay);
  void finished(const Job& j, int code);
  void draw();
  void say(const std::string& m);
  std::string job_line(const Job& j) const;

  const BatchSpec& b_;
  const std::vector<BatchTask>& tasks_;
  LocalRunOptions o_;
  bool tty_;
  int slots_ = 1, threads_ = 1;
  std::deque<Job> queue_;
  std::vector<Job> running_;
  int skipped_ = 0, done_ = 0, stopped_ = 0, previews_ = 0;
  std::vector<std::pair<int, int>> failed_;  ///< task index, exit code
  int drawn_lines_ = 0;
  int lock_fd_ = -1;
  double t0_ = 0;
};

void LocalEngine::plan_jobs() {
  for (const BatchTask& t : tasks_) {
    const std::optional<TaskStatus> st = read_task_status(b_, t.index);
    if (st && (st->fingerprint != hex_fingerprint(task_fingerprint(t)) || st->id != t.id()))
      throw UserError(b_.path, 0, "",
                      "task " + std::to_string(t.index) + " (" + t.id() + ") has changed since " +
                          "it ran (its scene, overrides or frames differ from " +
                          status_path(b_, t.index) + "); its folder " + t.output +
                          " holds the old caches. Remove that folder and the status file to "
                          "run it anew; nothing was started");
    const bool done = st && st->sim.state == TaskState::Done && !o_.force;
    if (done)
      ++skipped_;
    else
      queue_.push_back(Job{t.index, false});
    if (done && t.preview.enabled && st->preview.state != TaskState::Done)
      queue_.push_back(Job{t.index, true});
  }
}

void LocalEngine::say(const std::string& m) {
  if (o_.quiet) return;
  if (tty_ && drawn_lines_ > 0) {
    std::printf("\x1b[%dA\x1b[J", drawn_lines_);
    drawn_lines_ = 0;
  }
  std::printf("%s\n", m.c_str());
  std::fflush(stdout);
}

std::string LocalEngine::job_line(const Job& j) const {
  const BatchTask& t = tasks_[j.index];
  char buf[512];
  const double secs = unix_now() - j.start;
  if (j.preview)
    std::snprintf(buf, sizeof buf, "task %d %s: preview (%.0f s)", t.index, t.id().c_str(), secs);
  else
    std::snprintf(buf, sizeof buf, "task %d %s: frame %d/%d (%.0f s)", t.index, t.id().c_str(),
                  std::max(0, j.frames), t.frame_end - t.frame_start + 1, secs);
  return buf;
}

void LocalEngine::start(Job j) {
  const BatchTask& t = tasks_[j.index];
  std::vector<std::string> argv = {
      self_executable(),        "batch",    "task", b_.path, std::to_string(t.index), "--threads",
      std::to_string(threads_), "--engine", "local"};
  if (j.preview) argv.push_back("--preview");
  if (o_.force && !j.preview) argv.push_back("--force");
  j.pid = spawn_process(argv, log_path(b_, t.index), true);
  j.start = unix_now();
  running_.push_back(j);
  std::string what = j.preview ? "preview" : "start";
  if (!j.preview) {
    const std::string ck = latest_checkpoint(t.output, t.frame_end);
    if (!o_.force && !ck.empty()) what = "resume from " + ck;
  }
  say("task " + std::to_string(t.index) + " " + t.id() + ": " + what + " (" +
      std::to_string(threads_) + " thread" + (threads_ == 1 ? "" : "s") + ", log " +
      log_path(b_, t.index) + ")");
}

void LocalEngine::finished(const Job& j, int code) {
  const BatchTask& t = tasks_[j.index];
  char buf[256];
  std::snprintf(buf, sizeof buf, " after %.1f s", unix_now() - j.start);
  const std::string name = "task " + std::to_string(t.index) + " " + t.id();
  if (code == 0) {
    if (j.preview)
      ++previews_;
    else
      ++done_;
    say(name + (j.preview ? ": preview done" : ": done") + buf);
    if (!j.preview && t.preview.enabled && SignalRelay::pending() == 0)
      queue_.push_front(Job{t.index, true});
  } else if ((code == 143 || code == 130) && SignalRelay::pending() != 0) {
    ++stopped_;
    say(name + ": stopped with a checkpoint" + buf);
  } else {
    failed_.push_back({t.index, code});
    say(name + (j.preview ? ": preview failed" : ": failed") + " with exit " +
        std::to_string(code) + buf + " (log " + log_path(b_, t.index) + ")");
  }
}

void LocalEngine::poll(SignalRelay& relay) {
  for (std::size_t i = 0; i < running_.size();) {
    const int code = wait_process(running_[i].pid, true);
    if (code < 0) {
      ++i;
      continue;
    }
    relay.remove(running_[i].pid);
    const Job j = running_[i];
    running_.erase(running_.begin() + static_cast<std::ptrdiff_t>(i));
    finished(j, code);
  }
  for (Job& j : running_) {
    if (j.preview) continue;
    const int f = frames_done(tasks_[j.index]);
    if (f != j.frames) {
      j.frames = f;
      if (!tty_ && !o_.quiet && f > 0) say(job_line(j));
    }
  }
}

void LocalEngine::draw() {
  if (!tty_) return;
  if (drawn_lines_ > 0) std::printf("\x1b[%dA\x1b[J", drawn_lines_);
  drawn_lines_ = 0;
  for (const Job& j : running_) {
    std::printf("  %s\n", job_line(j).c_str());
    ++drawn_lines_;
  }
  std::printf("batch %s: %d done, %zu running, %zu queued, %zu failed, %d skipped (%.0f s)\n",
              b_.name.c_str(), done_, running_.size(), queue_.size(), failed_.size(), skipped_,
              unix_now() - t0_);
  ++drawn_lines_;
  std::fflush(stdout);
}

int LocalEngine::run() {
  plan_jobs();
  const int n = static_cast<int>(tasks_.size());
  if (queue_.empty()) {
    std::printf(
        "nothing to do: all %d tasks of batch %s are done (%s); `shellmpm batch status` "
        "shows them, --force runs them again\n",
        n, b_.name.c_str(), b_.output.c_str());
    return 0;
  }
  const int cores = available_cores();
  slots_ = o_.slots > 0 ? o_.slots : b_.farm.slots > 0 ? b_.farm.slots : std::max(1, cores);
  slots_ = std::min<int>(slots_, static_cast<int>(queue_.size()));
  threads_ = o_.threads > 0        ? o_.threads
             : b_.farm.threads > 0 ? b_.farm.threads
                                   : std::max(1, cores / slots_);
  write_task_table(b_, tasks_);
  // One `batch run` of a batch at a time (its tasks would wait for each other's locks).
  const std::string lock_path = farm_dir(b_) + "/run.lock";
  lock_fd_ = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd_ < 0 || flock(lock_fd_, LOCK_EX | LOCK_NB) != 0)
    throw UserError(lock_path, 0, "",
                    "another `shellmpm batch run` of this batch is running (it holds this "
                    "lock); `shellmpm batch status` follows it");
  if (!o_.quiet)
    std::printf("batch %s: %d tasks, %zu to run%s, %d at a time with %d thread%s each (%d cores)\n",
                b_.name.c_str(), n, queue_.size(),
                skipped_ ? (", " + std::to_string(skipped_) + " done already").c_str() : "", slots_,
                threads_, threads_ == 1 ? "" : "s", cores);
  SignalRelay relay(SignalRelay::Mode::Every);
  t0_ = unix_now();
  auto last_draw = std::chrono::steady_clock::now();
  while (!queue_.empty() || !running_.empty()) {
    while (static_cast<int>(running_.size()) < slots_ && !queue_.empty() &&
           SignalRelay::pending() == 0) {
      start(queue_.front());
      queue_.pop_front();
      relay.add(running_.back().pid);
    }
    if (SignalRelay::pending() != 0 && running_.empty()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    poll(relay);
    if (std::chrono::steady_clock::now() - last_draw > std::chrono::milliseconds(500)) {
      draw();
      last_draw = std::chrono::steady_clock::now();
    }
  }
  say("");
  const int left = static_cast<int>(queue_.size());
  std::printf(
      "batch %s: %d done, %d previews, %d skipped (done before), %zu failed, %d stopped%s "
      "in %.1f s\n",
      b_.name.c_str(), done_, previews_, skipped_, failed_.size(), stopped_,
      left ? (", " + std::to_string(left) + " not started").c_str() : "", unix_now() - t0_);
  for (const auto& [index, code] : failed_)
    std::fprintf(stderr, "error: task %d (%s) failed with exit %d; the end of %s:\n%s", index,
                 tasks_[index].id().c_str(), code, log_path(b_, index).c_str(),
                 log_tail(log_path(b_, index), 12).c_str());
  if (SignalRelay::pending() != 0) {
    std::fprintf(stderr,
                 "stopped by a signal: the running tasks wrote checkpoints; run the same "
                 "command again to continue\n");
    return 128 + SignalRelay::pending();
  }
  return failed_.empty() ? 0 : 1;
}

}  // namespace

int run_local(const BatchSpec& b, const std::vector<BatchTask>& tasks, const LocalRunOptions& o) {
  LocalEngine e(b, tasks, o);
  return e.run();
}

}  // namespace shellmpm

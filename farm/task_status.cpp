#include "farm/task_status.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/atomic_file.h"
#include "io/user_error.h"

namespace shellmpm {
namespace {

namespace fs = std::filesystem;

const char* const kStateWords[] = {"pending", "running", "stopped", "done", "failed"};

TaskState state_of_word(const std::string& w, const std::string& path) {
  for (int i = 0; i < 5; ++i)
    if (w == kStateWords[i]) return static_cast<TaskState>(i);
  throw UserError(path, 0, "state", "unknown task state '" + w + "'");
}

nlohmann::json step_json(const StepStatus& s) {
  nlohmann::json j;
  j["state"] = word_of_state(s.state);
  j["attempts"] = s.attempts;
  j["last_exit"] = s.last_exit;
  j["wall_seconds"] = s.wall_seconds;
  j["started"] = s.started;
  j["finished"] = s.finished;
  return j;
}

StepStatus step_of_json(const nlohmann::json& j, const std::string& path) {
  StepStatus s;
  s.state = state_of_word(j.at("state").get<std::string>(), path);
  s.attempts = j.at("attempts").get<int>();
  s.last_exit = j.at("last_exit").get<int>();
  s.wall_seconds = j.at("wall_seconds").get<double>();
  s.started = j.at("started").get<double>();
  s.finished = j.at("finished").get<double>();
  return s;
}

std::string padded(int index) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%04d", index);
  return buf;
}

}  // namespace

std::string word_of_state(TaskState s) {
  return kStateWords[static_cast<int>(s)];
}

std::string status_path(const BatchSpec& b, int index) {
  return farm_dir(b) + "/status/" + padded(index) + ".json";
}

std::string log_path(const BatchSpec& b, int index) {
  return farm_dir(b) + "/logs/task." + padded(index) + ".log";
}

std::optional<TaskStatus> read_task_status(const BatchSpec& b, int index) {
  const std::string path = status_path(b, index);
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream text;
  text << in.rdbuf();
  try {
    const nlohmann::json j = nlohmann::json::parse(text.str());
    TaskStatus s;
    s.index = j.at("index").get<int>();
    s.id = j.at("id").get<std::string>();
    s.fingerprint = j.at("fingerprint").get<std::string>();
    s.sim = step_of_json(j.at("sim"), path);
    s.preview = step_of_json(j.at("preview"), path);
    s.host = j.value("host", "");
    s.pid = j.value("pid", 0);
    s.engine = j.value("engine", "");
    s.job = j.value("job", "");
    return s;
  } catch (const nlohmann::json::exception& e) {
    throw UserError(path, 0, "", std::string("not a task status file: ") + e.what());
  }
}

void write_task_status(const BatchSpec& b, const TaskStatus& s) {
  nlohmann::json j;
  j["index"] = s.index;
  j["id"] = s.id;
  j["fingerprint"] = s.fingerprint;
  j["restarts"] = s.restarts();
  j["sim"] = step_json(s.sim);
  j["preview"] = step_json(s.preview);
  j["host"] = s.host;
  j["pid"] = s.pid;
  j["engine"] = s.engine;
  j["job"] = s.job;
  const std::string path = status_path(b, s.index);
  fs::create_directories(fs::path(path).parent_path());
  write_text_atomic(path, j.dump(2) + "\n");
}

int frames_done(const BatchTask& t) {
  std::ifstream in(t.output + "/stats.json", std::ios::binary);
  if (!in) return 0;
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, false);
  if (j.is_discarded() || !j.contains("frames") || !j["frames"].is_array()) return 0;
  int n = 0;
  for (const nlohmann::json& f : j["frames"])
    if (f.value("frame", 0) >= t.frame_start) ++n;
  return n;
}

std::string hex_fingerprint(std::uint64_t f) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(f));
  return buf;
}

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

}  // namespace shellmpm

#include "farm/batch_tasks.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/atomic_file.h"
#include "io/checkpoint.h"
#include "io/scene_reader.h"
#include "io/user_error.h"

namespace shellmpm {

namespace fs = std::filesystem;

std::vector<BatchTask> expand_tasks(const BatchSpec& b) {
  std::vector<BatchTask> tasks;
  for (const ShotSpec& s : b.shots) {
    const WedgeSpec* wedge = nullptr;
    for (const WedgeSpec& w : b.wedges)
      if (w.name == s.wedge) wedge = &w;
    std::vector<WedgeMember> members;
    if (wedge)
      members = wedge->members;
    else
      members.push_back(WedgeMember{"base", {}});
    for (const WedgeMember& m : members) {
      BatchTask t;
      t.index = static_cast<int>(tasks.size());
      t.shot = s.name;
      t.wedge = m.name;
      t.wedge_values = m.values;
      t.overrides = s.overrides;
      t.overrides.insert(t.overrides.end(), m.values.begin(), m.values.end());
      t.scene = s.scene;
      t.frames_from_batch = s.frame_start.has_value();
      if (t.frames_from_batch) {
        t.frame_start = *s.frame_start;
        t.frame_end = *s.frame_end;
      }
      t.output = (fs::path(b.output) / s.name / m.name).lexically_normal().string();
      t.preview = s.preview;
      tasks.push_back(t);
    }
  }
  return tasks;
}

void rethrow_for_task(const UserError& e, const BatchTask& t) {
  for (const Override& o : t.overrides) {
    if (e.file != "--set " + o.arg()) continue;
    const std::string what = e.key.empty() || e.key == o.key ? e.message : e.key + ": " + e.message;
    throw UserError(o.origin.where, o.origin.line, o.where_key,
                    what + " (task " + std::to_string(t.index) + ", " + t.id() + ")");
  }
  throw UserError(e.file, e.line, e.key,
                  e.message + " (task " + std::to_string(t.index) + ", " + t.id() + ")");
}

void resolve_frames(std::vector<BatchTask>& tasks) {
  for (BatchTask& t : tasks) {
    std::vector<std::string> sets;
    for (const Override& o : t.overrides) sets.push_back(o.arg());
    try {
      const Scene scene = read_scene(t.scene, sets);
      if (!t.frames_from_batch) {
        t.frame_start = scene.shot.frame_start;
        t.frame_end = scene.shot.frame_end;
      }
    } catch (const UserError& e) {
      rethrow_for_task(e, t);
    }
  }
}

std::vector<std::string> run_arguments(const BatchTask& t) {
  std::vector<std::string> args = {t.scene};
  if (t.frames_from_batch)
    args.insert(args.end(),
                {"--frames", std::to_string(t.frame_start) + "-" + std::to_string(t.frame_end)});
  args.insert(args.end(), {"--output", t.output});
  for (const Override& o : t.overrides) args.insert(args.end(), {"--set", o.arg()});
  return args;
}

std::uint64_t task_fingerprint(const BatchTask& t) {
  std::ifstream in(t.scene, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  for (const Override& o : t.overrides) s += "\n--set " + o.arg();
  if (t.frames_from_batch)
    s += "\n--frames " + std::to_string(t.frame_start) + "-" + std::to_string(t.frame_end);
  return fingerprint(s);
}

std::string farm_dir(const BatchSpec& b) {
  return (fs::path(b.output) / "_farm").string();
}

nlohmann::json task_json(const BatchTask& t) {
  nlohmann::json j;
  j["index"] = t.index;
  j["shot"] = t.shot;
  j["wedge"] = t.wedge;
  nlohmann::json values = nlohmann::json::object();
  for (const Override& o : t.wedge_values) values[o.key] = o.value;
  j["values"] = values;
  nlohmann::json sets = nlohmann::json::array();
  for (const Override& o : t.overrides) sets.push_back(o.arg());
  j["set"] = sets;
  j["scene"] = t.scene;
  j["frames"] = {t.frame_start, t.frame_end};
  j["output"] = t.output;
  j["preview"] = t.preview.enabled;
  return j;
}

nlohmann::json task_table_json(const BatchSpec& b, const std::vector<BatchTask>& tasks) {
  nlohmann::json j;
  j["batch"] = b.path;
  j["name"] = b.name;
  j["output"] = b.output;
  j["tasks"] = nlohmann::json::array();
  for (const BatchTask& t : tasks) j["tasks"].push_back(task_json(t));
  return j;
}

std::string values_text(const BatchTask& t) {
  std::string s;
  for (const Override& o : t.wedge_values) s += (s.empty() ? "" : " ") + o.key + "=" + o.value;
  return s.empty() ? "-" : s;
}

void write_task_table(const BatchSpec& b, const std::vector<BatchTask>& tasks) {
  const std::string dir = farm_dir(b);
  fs::create_directories(dir);
  write_text_atomic(dir + "/tasks.json", task_table_json(b, tasks).dump(2) + "\n");
  std::string tsv = "index\tshot\twedge\tvalues\tframes\toutput\n";
  for (const BatchTask& t : tasks)
    tsv += std::to_string(t.index) + "\t" + t.shot + "\t" + t.wedge + "\t" + values_text(t) + "\t" +
           std::to_string(t.frame_start) + "-" + std::to_string(t.frame_end) + "\t" + t.output +
           "\n";
  write_text_atomic(dir + "/tasks.tsv", tsv);
}

}  // namespace shellmpm

#include "farm/wedge_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

namespace shellmpm {
namespace {

enum class Fold { Last, Max, Min, Sum };

struct FigureDef {
  const char* name;  ///< column name
  const char* key;   ///< stats.json per-frame key
  Fold fold;
};

/// The figures of a run's stats.json that the wedge table shows, when some task has them.
const FigureDef kFigures[] = {
    {"substeps", "substeps", Fold::Sum},
    {"dt_min", "dt_min", Fold::Min},
    {"max_speed", "max_speed", Fold::Max},
    {"kinetic_energy", "kinetic_energy", Fold::Last},
    {"elastic_energy", "elastic_energy", Fold::Last},
    {"mass", "mass", Fold::Last},
    {"shell_max_strain", "shell_max_strain", Fold::Max},
    {"shell_plastic_work", "shell_plastic_work", Fold::Last},
    {"contact_energy", "contact_energy", Fold::Last},
    {"friction_work", "friction_work", Fold::Last},
    {"guard_unresolved", "guard_unresolved", Fold::Sum},
};

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double fold_frames(const nlohmann::json& frames, const FigureDef& d) {
  double acc = kNaN;
  for (const nlohmann::json& f : frames) {
    if (!f.contains(d.key) || !f[d.key].is_number()) continue;
    const double x = f[d.key].get<double>();
    if (d.fold == Fold::Min && x <= 0) continue;  // frame 1 takes no step: dt_min 0
    if (std::isnan(acc))
      acc = x;
    else if (d.fold == Fold::Max)
      acc = std::max(acc, x);
    else if (d.fold == Fold::Min)
      acc = std::min(acc, x);
    else if (d.fold == Fold::Sum)
      acc += x;
    else
      acc = x;
  }
  return acc;
}

/// "ok", "-" (no monitor), or "failed: N kind (object), ..." over every frame.
std::string integrity_of(const nlohmann::json& frames) {
  bool active = false, ok = true;
  std::map<std::string, long long> events;
  for (const nlohmann::json& f : frames) {
    if (!f.contains("integrity")) continue;
    const nlohmann::json& in = f["integrity"];
    active = true;
    ok = ok && in.value("ok", true);
    if (!in.contains("events")) continue;
    for (const nlohmann::json& e : in["events"])
      events[e.value("kind", "?") + " (" + e.value("object", "?") + ")"] += e.value("count", 1LL);
  }
  if (!active) return "-";
  if (ok && events.empty()) return "ok";
  std::string s = ok ? "ok, events:" : "failed:";
  for (const auto& [what, n] : events) s += " " + std::to_string(n) + " " + what + ";";
  if (s.back() == ';') s.pop_back();
  return s;
}

nlohmann::json read_frames(const BatchTask& t) {
  std::ifstream in(t.output + "/stats.json", std::ios::binary);
  if (!in) return nlohmann::json::array();
  std::stringstream text;
  text << in.rdbuf();
  const nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, false);
  if (j.is_discarded() || !j.contains("frames")) return nlohmann::json::array();
  nlohmann::json frames = nlohmann::json::array();
  for (const nlohmann::json& f : j["frames"])
    if (f.value("frame", 0) >= t.frame_start) frames.push_back(f);
  return frames;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

/// The columns shared by CSV and Markdown: header and per-row cells.
std::vector<std::string> header(const WedgeTable& t) {
  std::vector<std::string> h = {"task", "shot", "wedge"};
  h.insert(h.end(), t.value_keys.begin(), t.value_keys.end());
  h.insert(h.end(), {"state", "frames", "restarts", "wall_seconds"});
  h.insert(h.end(), t.figure_names.begin(), t.figure_names.end());
  h.insert(h.end(), {"integrity", "output"});
  return h;
}

std::vector<std::string> cells(const WedgeRow& r) {
  const BatchTask& t = *r.task;
  std::vector<std::string> c = {std::to_string(t.index), t.shot, t.wedge};
  c.insert(c.end(), r.values.begin(), r.values.end());
  c.push_back(r.state);
  c.push_back(std::to_string(r.frames_done) + "/" +
              std::to_string(t.frame_end - t.frame_start + 1));
  c.push_back(r.status ? std::to_string(r.status->restarts()) : "0");
  c.push_back(r.status ? figure_text(r.status->sim.wall_seconds) : "");
  for (double x : r.figures) c.push_back(figure_text(x));
  c.push_back(r.integrity);
  c.push_back(t.output);
  return c;
}

}  // namespace

std::string figure_text(double x) {
  if (std::isnan(x)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

WedgeTable build_wedge_table(const BatchSpec& b, const std::vector<BatchTask>& tasks) {
  WedgeTable table;
  for (const BatchTask& t : tasks)
    for (const Override& o : t.wedge_values)
      if (std::find(table.value_keys.begin(), table.value_keys.end(), o.key) ==
          table.value_keys.end())
        table.value_keys.push_back(o.key);
  std::vector<std::vector<double>> all;
  for (const BatchTask& t : tasks) {
    WedgeRow r;
    r.task = &t;
    r.status = read_task_status(b, t.index);
    r.state = r.status ? word_of_state(r.status->sim.state) : "pending";
    r.frames = read_frames(t);
    r.frames_done = static_cast<int>(r.frames.size());
    for (const std::string& k : table.value_keys) {
      std::string v;
      for (const Override& o : t.wedge_values)
        if (o.key == k) v = o.value;
      r.values.push_back(v);
    }
    std::vector<double> f;
    for (const FigureDef& d : kFigures) f.push_back(fold_frames(r.frames, d));
    all.push_back(f);
    r.integrity = integrity_of(r.frames);
    table.rows.push_back(r);
  }
  // Only the figures some task has.
  for (std::size_t k = 0; k < std::size(kFigures); ++k) {
    const bool any = std::any_of(all.begin(), all.end(),
                                 [&](const std::vector<double>& f) { return !std::isnan(f[k]); });
    if (!any) continue;
    table.figure_names.push_back(kFigures[k].name);
    for (std::size_t i = 0; i < table.rows.size(); ++i) table.rows[i].figures.push_back(all[i][k]);
  }
  return table;
}

std::string wedge_csv(const WedgeTable& t) {
  std::string s;
  auto line = [&s](const std::vector<std::string>& c) {
    for (std::size_t i = 0; i < c.size(); ++i) s += (i ? "," : "") + csv_field(c[i]);
    s += "\n";
  };
  line(header(t));
  for (const WedgeRow& r : t.rows) line(cells(r));
  return s;
}

std::string wedge_markdown(const WedgeTable& t) {
  std::string s;
  auto line = [&s](const std::vector<std::string>& c) {
    s += "|";
    for (const std::string& x : c) {
      std::string e;
      for (char ch : x) e += ch == '|' ? std::string("\\|") : std::string(1, ch);
      s += " " + (e.empty() ? std::string("-") : e) + " |";
    }
    s += "\n";
  };
  const std::vector<std::string> h = header(t);
  line(h);
  s += "|";
  for (std::size_t i = 0; i < h.size(); ++i) s += "---|";
  s += "\n";
  for (const WedgeRow& r : t.rows) line(cells(r));
  return s;
}

nlohmann::json wedge_json(const BatchSpec& b, const WedgeTable& t) {
  nlohmann::json j;
  j["batch"] = b.path;
  j["name"] = b.name;
  j["value_keys"] = t.value_keys;
  j["figures"] = t.figure_names;
  j["tasks"] = nlohmann::json::array();
  for (const WedgeRow& r : t.rows) {
    const BatchTask& task = *r.task;
    nlohmann::json e;
    e["index"] = task.index;
    e["shot"] = task.shot;
    e["wedge"] = task.wedge;
    nlohmann::json values = nlohmann::json::object();
    for (std::size_t k = 0; k < t.value_keys.size(); ++k)
      if (!r.values[k].empty()) values[t.value_keys[k]] = r.values[k];
    e["values"] = values;
    e["state"] = r.state;
    e["frames_done"] = r.frames_done;
    e["frames"] = task.frame_end - task.frame_start + 1;
    e["restarts"] = r.status ? r.status->restarts() : 0;
    e["wall_seconds"] = r.status ? r.status->sim.wall_seconds : 0.0;
    nlohmann::json fig = nlohmann::json::object();
    for (std::size_t k = 0; k < t.figure_names.size(); ++k)
      fig[t.figure_names[k]] =
          std::isnan(r.figures[k]) ? nlohmann::json() : nlohmann::json(r.figures[k]);
    e["stats"] = fig;
    e["integrity"] = r.integrity;
    e["output"] = task.output;
    j["tasks"].push_back(e);
  }
  return j;
}

}  // namespace shellmpm

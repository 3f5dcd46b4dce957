#include "study/convergence.h"

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "io/scene_reader.h"
#include "study/child_run.h"
#include "io/user_error.h"

namespace shellmpm {

VarySpec parse_vary(const std::string& text) {
  const std::string where = "--vary " + text;
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw UserError(where, 0, "", "expected KEY=V1,V2,... (e.g. shot.dx=0.04,0.02,0.01)");
  VarySpec v;
  v.key = text.substr(0, eq);
  std::string cur;
  int depth = 0;
  for (char c : text.substr(eq + 1)) {
    if (c == '[' || c == '{') ++depth;
    if (c == ']' || c == '}') --depth;
    if (c == ',' && depth == 0) {
      v.values.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  v.values.push_back(cur);
  for (const std::string& s : v.values)
    if (s.find_first_not_of(" \t") == std::string::npos)
      throw UserError(where, 0, v.key, "an empty value in the list");
  if (v.values.size() < 2)
    throw UserError(where, 0, v.key, "give at least two values, separated by commas");
  return v;
}

std::optional<double> spacing_of_value(const std::string& value) {
  std::string s = value;
  const std::size_t a = s.find_first_not_of(" \t[");
  if (a == std::string::npos) return std::nullopt;
  s = s.substr(a);
  const std::size_t b = s.find_first_of(",] \t");
  if (b != std::string::npos) s = s.substr(0, b);
  if (s.empty()) return std::nullopt;
  const bool integer = s.find_first_not_of("+-0123456789") == std::string::npos;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || *end != '\0' || !std::isfinite(v) || v <= 0) return std::nullopt;
  return integer ? 1.0 / v : v;
}

namespace {

void log_line(const ConvergeOptions& o, const std::string& m) {
  if (o.log) o.log(m);
}

}  // namespace

ConvergeResult run_convergence(const ConvergeOptions& opt) {
  if (opt.vary.empty()) throw UserError("--vary", 0, "", "give at least one --vary KEY=V1,V2");
  const std::size_t n = opt.vary.front().values.size();
  for (const VarySpec& v : opt.vary)
    if (v.values.size() != n)
      throw UserError("--vary " + v.key, 0, v.key,
                      "has " + std::to_string(v.values.size()) + " values, the first --vary " +
                          std::to_string(n) + ": keys varied together need as many values");
  if (!opt.spacing.empty() && opt.spacing.size() != n)
    throw UserError("--h", 0, "",
                    "gives " + std::to_string(opt.spacing.size()) + " spacings for " +
                        std::to_string(n) + " settings");

  ConvergeResult res;
  res.quantity = opt.measure;
  std::vector<Scene> scenes;
  std::optional<Quantity> q;
  for (std::size_t i = 0; i < n; ++i) {
    ConvergeSetting s;
    for (const VarySpec& v : opt.vary) {
      s.overrides.push_back(v.key + "=" + v.values[i]);
      s.label += (s.label.empty() ? "" : " ") + v.key + "=" + v.values[i];
    }
    std::vector<std::string> all = opt.overrides;
    all.insert(all.end(), s.overrides.begin(), s.overrides.end());
    scenes.push_back(read_scene(opt.scene, all));
    if (!q) q = parse_quantity(opt.measure, scenes.back(), "--measure");
    if (!opt.spacing.empty()) {
      s.h = opt.spacing[i];
    } else {
      const auto h = spacing_of_value(opt.vary.front().values[i]);
      s.h = h ? *h : 0;
    }
    res.settings.push_back(s);
  }

  for (std::size_t i = 0; i < n; ++i) {
    ConvergeSetting& s = res.settings[i];
    ChildRunRequest req;
    req.binary = opt.binary;
    req.scene = opt.scene;
    req.output = (std::filesystem::path(opt.output) / ("setting" + std::to_string(i + 1))).string();
    req.threads = opt.threads;
    req.frames = opt.frames;
    req.overrides = opt.overrides;
    const std::vector<std::string> outs = run_outputs_overrides(q->needs_particles());
    req.overrides.insert(req.overrides.end(), outs.begin(), outs.end());
    req.overrides.insert(req.overrides.end(), s.overrides.begin(), s.overrides.end());
    std::filesystem::create_directories(req.output);
    req.log = req.output + "/run.log";
    log_line(opt, "running " + s.label + " ...");
    const ChildRunResult cr = run_child(req);
    s.wall_seconds = cr.wall_seconds;
    s.peak_rss_bytes = cr.peak_rss_bytes;
    if (cr.exit_code != 0)
      throw std::runtime_error("the run with " + s.label + " failed (exit " +
                               std::to_string(cr.exit_code) + ", log " + req.log +
                               "): " + cr.log_tail);
    const RunFolder rf(req.output);
    for (const nlohmann::json& f : rf.frames()) s.substeps += f.value("substeps", 0L);
    const int frame = opt.at_frame > 0 ? opt.at_frame : rf.last_frame();
    s.value = evaluate_quantity(*q, rf, frame);
    log_line(opt, "  " + q->text + " = " + std::to_string(s.value) + " (" +
                      std::to_string(s.wall_seconds) + " s)");
    if (!opt.keep_runs) std::filesystem::remove_all(req.output);
  }

  std::vector<double> h, v;
  for (const ConvergeSetting& s : res.settings)
    if (s.h > 0) {
      h.push_back(s.h);
      v.push_back(s.value);
    }
  if (h.size() == n) res.extrapolation = richardson(h, v);
  // The next refinement: the two finest settings' spacing ratio and cost growth, continued.
  if (h.size() == n && n >= 2) {
    std::size_t a = 0, b = 1;  // a: finest, b: next finest
    if (h[b] < h[a]) std::swap(a, b);
    for (std::size_t i = 2; i < n; ++i) {
      if (h[i] < h[a]) {
        b = a;
        a = i;
      } else if (h[i] < h[b]) {
        b = i;
      }
    }
    const double ratio = h[b] / h[a];
    const double ta = res.settings[a].wall_seconds, tb = res.settings[b].wall_seconds;
    if (ratio > 1 && ta > 0 && tb > 0) {
      res.next_spacing = h[a] / ratio;
      res.next_cost_seconds = ta * (ta / tb);
    }
  }
  return res;
}

std::string convergence_json(const ConvergeResult& r) {
  nlohmann::json j;
  j["quantity"] = r.quantity;
  nlohmann::json s = nlohmann::json::array();
  for (const ConvergeSetting& c : r.settings)
    s.push_back({{"setting", c.label},
                 {"overrides", c.overrides},
                 {"h", c.h},
                 {"value", c.value},
                 {"wall_seconds", c.wall_seconds},
                 {"substeps", c.substeps},
                 {"peak_rss_bytes", c.peak_rss_bytes}});
  j["settings"] = s;
  if (r.extrapolation)
    j["richardson"] = {{"order", r.extrapolation->order},
                       {"limit", r.extrapolation->limit},
                       {"error_of_finest", r.extrapolation->error}};
  if (r.next_cost_seconds) {
    j["next_spacing"] = *r.next_spacing;
    j["next_cost_seconds"] = *r.next_cost_seconds;
  }
  return j.dump(2) + "\n";
}

}  // namespace shellmpm

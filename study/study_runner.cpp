#include "study/study_runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "io/scene_reader.h"
#include "study/child_run.h"
#include "io/user_error.h"

namespace shellmpm {

namespace {

namespace fs = std::filesystem;

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : sep) + x;
  return s;
}

std::string fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

/// The problems named in opt (all when none), in the table's order.
std::vector<ReferenceProblem> selected(const StudyOptions& opt) {
  std::vector<ReferenceProblem> all = reference_problems();
  if (opt.problems.empty() || (opt.problems.size() == 1 && opt.problems[0] == "all")) return all;
  std::vector<ReferenceProblem> out;
  for (const std::string& name : opt.problems) {
    bool found = false;
    for (const ReferenceProblem& p : all)
      if (p.name == name) {
        out.push_back(p);
        found = true;
      }
    if (!found) {
      std::vector<std::string> names;
      for (const ReferenceProblem& p : all) names.push_back(p.name);
      throw UserError("--suite " + name, 0, "",
                      "no such reference problem (problems: " + join(names, ", ") + ", all)");
    }
  }
  return out;
}

/// Fills the run's counts and simulated time from its stats.json.
void read_counts(const RunFolder& rf, StudyRun& r) {
  long substeps = 0;
  for (const nlohmann::json& f : rf.frames()) substeps += f.value("substeps", 0L);
  const nlohmann::json& last = rf.frames().back();
  r.substeps = substeps;
  r.particles = last.value("particles", 0L);
  r.shell_points = last.value("shell_points", 0L);
  r.contact_particles = last.value("contact_particles", 0L);
  r.simulated_seconds = rf.time(rf.last_frame()) - rf.time(rf.first_frame());
  r.cost = r.simulated_seconds > 0 ? r.wall_seconds / r.simulated_seconds : r.wall_seconds;
}

void run_one(const StudyOptions& opt, const ReferenceProblem& p, const std::string& scene_path,
             const Scene& scene, const std::string& dir, StudyRun& r) {
  ChildRunRequest req;
  req.binary = opt.binary;
  req.scene = scene_path;
  req.output = dir;
  req.threads = opt.threads;
  req.overrides = run_outputs_overrides(p.needs_particles);
  req.overrides.insert(req.overrides.end(), r.overrides.begin(), r.overrides.end());
  fs::create_directories(dir);
  req.log = dir + "/run.log";
  const ChildRunResult cr = run_child(req);
  r.wall_seconds = cr.wall_seconds;
  r.peak_rss_bytes = cr.peak_rss_bytes;
  if (cr.exit_code != 0) {
    r.status = "failed";
    r.note = "exit " + std::to_string(cr.exit_code) + ": " + cr.log_tail;
    return;
  }
  try {
    const RunFolder rf(dir);
    read_counts(rf, r);
    r.value = p.measure(rf, scene);
    r.error =
        p.relative_error ? (r.value - r.reference) / std::abs(r.reference) : r.value - r.reference;
    r.status = std::isfinite(r.error) ? "ok" : "failed";
    if (r.status != "ok") r.note = "the measurement is not finite";
    if (r.status == "ok" && p.doubt) {
      r.note = p.doubt(rf, scene);
      if (!r.note.empty()) r.status = "doubtful";
    }
  } catch (const std::exception& e) {
    r.status = "failed";
    r.note = e.what();
  }
}

void fit_sweep(StudyProblemResult& pr, StudySweepResult& sw) {
  if (!sw.refinement) return;
  std::vector<double> h, err, q;
  for (int i : sw.runs) {
    const StudyRun& r = pr.runs[i];
    if (r.status != "ok" || r.h <= 0) continue;
    h.push_back(r.h);
    err.push_back(r.error);
    q.push_back(r.value);
  }
  sw.fitted_order = fitted_order(h, err);
  sw.extrapolation = richardson(h, q);
}

}  // namespace

void mark_pareto_front(std::vector<StudyRun>& runs) {
  for (StudyRun& a : runs) {
    a.pareto = false;
    if (a.status != "ok" || a.reused_from >= 0) continue;
    bool dominated = false;
    for (const StudyRun& b : runs) {
      if (&a == &b || b.status != "ok" || b.reused_from >= 0) continue;
      const double ea = std::abs(a.error), eb = std::abs(b.error);
      if (b.cost <= a.cost && eb <= ea && (b.cost < a.cost || eb < ea)) {
        dominated = true;
        break;
      }
    }
    a.pareto = !dominated;
  }
}

StudyResults run_study(const StudyOptions& opt) {
  const std::vector<ReferenceProblem> problems = selected(opt);
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  auto log = [&](const std::string& m) {
    if (opt.log) opt.log(m);
  };

  // Plan: every setting's scene read up front (errors before hours of computing).
  struct Planned {
    std::string scene_path;
    std::vector<Scene> scenes;  // per run
  };
  StudyResults out;
  out.threads = opt.threads;
  out.budget_seconds = opt.budget_seconds;
  out.quick = opt.quick;
  std::vector<Planned> plans;
  for (const ReferenceProblem& p : problems) {
    StudyProblemResult pr;
    pr.name = p.name;
    pr.title = p.title;
    pr.quantity = p.quantity;
    pr.unit = p.unit;
    pr.reference_source = p.reference_source;
    pr.relative_error = p.relative_error;
    Planned plan;
    plan.scene_path = (fs::path(opt.scenes_dir) / (p.name + ".yaml")).string();
    std::map<std::string, int> by_overrides;
    for (std::size_t si = 0; si < p.sweeps.size(); ++si) {
      if (opt.quick && si > 0) break;
      const StudySweep& sw = p.sweeps[si];
      if (!opt.sweeps.empty() &&
          std::find(opt.sweeps.begin(), opt.sweeps.end(), sw.name) == opt.sweeps.end())
        continue;
      StudySweepResult swr;
      swr.name = sw.name;
      swr.varied = sw.varied;
      swr.held = sw.held;
      swr.refinement = sw.refinement;
      for (std::size_t k = 0; k < sw.settings.size(); ++k) {
        if (opt.quick && k >= 2) break;
        const StudySetting& st = sw.settings[k];
        StudyRun r;
        r.sweep = sw.name;
        r.label = st.label;
        r.overrides = st.overrides;
        r.h = st.h;
        const Scene scene = read_scene(plan.scene_path, st.overrides);
        r.reference = p.reference(scene);
        r.dx = scene.shot.dx;
        const std::string key = join(st.overrides, "\n");
        const auto same = by_overrides.find(key);
        if (same != by_overrides.end())
          r.reused_from = same->second;
        else
          by_overrides[key] = static_cast<int>(pr.runs.size());
        swr.runs.push_back(static_cast<int>(pr.runs.size()));
        pr.runs.push_back(r);
        plan.scenes.push_back(scene);
      }
      pr.sweeps.push_back(swr);
    }
    out.problems.push_back(pr);
    plans.push_back(plan);
  }

  for (std::size_t pi = 0; pi < problems.size(); ++pi) {
    const ReferenceProblem& p = problems[pi];
    StudyProblemResult& pr = out.problems[pi];
    for (std::size_t i = 0; i < pr.runs.size(); ++i) {
      StudyRun& r = pr.runs[i];
      if (r.reused_from >= 0) {
        const StudyRun& src = pr.runs[r.reused_from];
        const std::string sweep = r.sweep, label = r.label;
        const int from = r.reused_from;
        r = src;
        r.sweep = sweep;
        r.label = label;
        r.reused_from = from;
        continue;
      }
      if (elapsed() >= opt.budget_seconds) {
        r.status = "skipped";
        r.note = "budget of " + fixed(opt.budget_seconds, 0) + " s spent";
        log(p.name + " " + r.label + ": skipped (budget spent)");
        continue;
      }
      const std::string dir =
          (fs::path(opt.output) / "runs" / p.name / ("run" + std::to_string(i))).string();
      std::error_code ec;
      fs::remove_all(dir, ec);
      run_one(opt, p, plans[pi].scene_path, plans[pi].scenes[i], dir, r);
      // Measured runs go (the doubtful ones too: their measurement is in the results);
      // failed ones stay for their logs.
      if (!opt.keep_runs && (r.status == "ok" || r.status == "doubtful")) fs::remove_all(dir, ec);
      const bool measured = r.status == "ok" || r.status == "doubtful";
      log(p.name + " [" + r.sweep + "] " + r.label + ": " +
          (measured ? "value " + std::to_string(r.value) + " " + p.unit + ", reference " +
                          std::to_string(r.reference) + ", error " +
                          (p.relative_error ? fixed(100 * r.error, 2) + "%"
                                            : std::to_string(r.error) + " " + p.unit) +
                          ", " + fixed(r.wall_seconds, 1) + " s"
                    : r.status) +
          (r.note.empty()
               ? std::string()
               : " (" + std::string(r.status == "doubtful" ? "doubtful: " : "") + r.note + ")"));
    }
    mark_pareto_front(pr.runs);
    for (StudySweepResult& sw : pr.sweeps) fit_sweep(pr, sw);
  }
  out.wall_seconds = elapsed();
  return out;
}

}  // namespace shellmpm

#include "study/study_report.h"

#include <cmath>
#include <sstream>
#include <thread>

#include "io/atomic_file.h"

namespace shellmpm {

namespace {

nlohmann::json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json run_json(const StudyRun& r) {
  nlohmann::json j;
  j["sweep"] = r.sweep;
  j["label"] = r.label;
  j["overrides"] = r.overrides;
  j["h"] = r.h;
  j["dx"] = r.dx;
  j["status"] = r.status;
  if (!r.note.empty()) j["note"] = r.note;
  j["value"] = number_or_null(r.value);
  j["reference"] = number_or_null(r.reference);
  j["error"] = number_or_null(r.error);
  j["wall_seconds"] = r.wall_seconds;
  j["simulated_seconds"] = r.simulated_seconds;
  j["cost"] = r.cost;
  j["substeps"] = r.substeps;
  j["particles"] = r.particles;
  j["shell_points"] = r.shell_points;
  j["contact_particles"] = r.contact_particles;
  j["peak_rss_bytes"] = r.peak_rss_bytes;
  j["pareto"] = r.pareto;
  if (r.reused_from >= 0) j["same_as_run"] = r.reused_from;
  return j;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string g(double v, int precision = 6) {
  if (!std::isfinite(v)) return "";
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

std::string error_text(const StudyProblemResult& p, double e) {
  if (!std::isfinite(e)) return "-";
  if (p.relative_error) return g(100 * e, 3) + "%";
  return g(e, 3) + " " + p.unit;
}

}  // namespace

nlohmann::json study_json(const StudyResults& r) {
  nlohmann::json j;
  j["wall_seconds"] = r.wall_seconds;
  j["threads"] = r.threads;
  j["hardware_threads"] = std::thread::hardware_concurrency();
  j["budget_seconds"] = r.budget_seconds;
  j["quick"] = r.quick;
#ifdef SHELLMPM_DOUBLE
  j["precision"] = "double";
#else
  j["precision"] = "float";
#endif
  nlohmann::json problems = nlohmann::json::array();
  for (const StudyProblemResult& p : r.problems) {
    nlohmann::json pj;
    pj["name"] = p.name;
    pj["title"] = p.title;
    pj["quantity"] = p.quantity;
    pj["unit"] = p.unit;
    pj["reference_source"] = p.reference_source;
    pj["error_kind"] = p.relative_error ? "relative" : "absolute";
    pj["cost_unit"] = (!p.runs.empty() && p.runs.front().simulated_seconds == 0)
                          ? "wall seconds"
                          : "wall seconds per simulated second";
    nlohmann::json runs = nlohmann::json::array();
    for (const StudyRun& run : p.runs) runs.push_back(run_json(run));
    pj["runs"] = runs;
    nlohmann::json sweeps = nlohmann::json::array();
    for (const StudySweepResult& s : p.sweeps) {
      nlohmann::json sj;
      sj["name"] = s.name;
      sj["varied"] = s.varied;
      sj["held"] = s.held;
      sj["refinement"] = s.refinement;
      sj["runs"] = s.runs;
      if (s.fitted_order) sj["fitted_order"] = *s.fitted_order;
      if (s.extrapolation) {
        sj["richardson"] = {{"order", s.extrapolation->order},
                            {"limit", s.extrapolation->limit},
                            {"error_of_finest", s.extrapolation->error}};
      }
      sweeps.push_back(sj);
    }
    pj["sweeps"] = sweeps;
    problems.push_back(pj);
  }
  j["problems"] = problems;
  return j;
}

void write_study_report(const StudyResults& r, const std::string& output) {
  write_text_atomic(output + "/results.json", study_json(r).dump(2) + "\n");

  std::ostringstream csv;
  csv << "problem,sweep,label,overrides,h,dx,status,value,reference,error,error_kind,"
         "wall_seconds,simulated_seconds,cost,substeps,particles,shell_points,"
         "contact_particles,peak_rss_bytes,pareto,note\n";
  for (const StudyProblemResult& p : r.problems)
    for (const StudyRun& run : p.runs) {
      std::string ov;
      for (const std::string& o : run.overrides) ov += (ov.empty() ? "" : " ") + o;
      csv << csv_field(p.name) << ',' << csv_field(run.sweep) << ',' << csv_field(run.label) << ','
          << csv_field(ov) << ',' << g(run.h) << ',' << g(run.dx) << ',' << run.status << ','
          << g(run.value, 8) << ',' << g(run.reference, 8) << ',' << g(run.error, 6) << ','
          << (p.relative_error ? "relative" : "absolute") << ',' << g(run.wall_seconds, 4) << ','
          << g(run.simulated_seconds, 6) << ',' << g(run.cost, 5) << ',' << run.substeps << ','
          << run.particles << ',' << run.shell_points << ',' << run.contact_particles << ','
          << g(run.peak_rss_bytes, 6) << ',' << (run.pareto ? 1 : 0) << ',' << csv_field(run.note)
          << '\n';
    }
  write_text_atomic(output + "/results.csv", csv.str());

  std::ostringstream md;
  md << "# Accuracy study results\n\n"
     << "Threads: " << r.threads << " (0: all cores), study wall time " << g(r.wall_seconds, 4)
     << " s" << (r.quick ? ", quick run" : "") << ".\n";
  for (const StudyProblemResult& p : r.problems) {
    md << "\n## " << p.title << " (`" << p.name << "`)\n\n"
       << "Quantity: " << p.quantity << " [" << p.unit << "]. Reference: " << p.reference_source
       << ".\n\n"
       << "| sweep | setting | value | reference | error | wall s | cost | substeps | points "
          "| peak MB | front |\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const StudyRun& run : p.runs) {
      const long points = run.particles + run.shell_points;
      md << "| " << run.sweep << " | " << run.label << " | "
         << (run.status == "ok"         ? g(run.value, 5)
             : run.status == "doubtful" ? g(run.value, 5) + " (doubtful)"
                                        : run.status)
         << " | " << g(run.reference, 5) << " | " << error_text(p, run.error) << " | "
         << g(run.wall_seconds, 3) << " | " << g(run.cost, 3) << " | " << run.substeps << " | "
         << points << " | " << g(run.peak_rss_bytes / 1e6, 3) << " | " << (run.pareto ? "yes" : "")
         << " |\n";
    }
    for (const StudyRun& run : p.runs)
      if (!run.note.empty() && run.status != "skipped")
        md << "\n- " << run.label << ", " << run.status << ": " << run.note;
    md << "\n";
    for (const StudySweepResult& s : p.sweeps) {
      if (!s.refinement) continue;
      md << "\n" << s.name << " (" << s.varied << "; held: " << s.held << "): ";
      md << (s.fitted_order ? "fitted order " + g(*s.fitted_order, 3) : "no order fitted");
      if (s.extrapolation)
        md << ", Richardson order " << g(s.extrapolation->order, 3) << ", limit "
           << g(s.extrapolation->limit, 6) << " " << p.unit;
      md << ".\n";
    }
  }
  write_text_atomic(output + "/summary.md", md.str());
}

}  // namespace shellmpm

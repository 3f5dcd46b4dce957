// The accuracy-vs-time study: runs every reference problem (study/reference_problem.h)
// over its sweeps as child `shellmpm run`s, measures each against its reference, and
// records what it cost (wall time, time per simulated second, substeps, counts, peak
// memory). The Pareto front and the convergence orders are computed here; the report
// (study/study_report.h) writes them out.
#pragma once
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "study/reference_problem.h"
#include "study/richardson.h"

namespace shellmpm {

struct StudyOptions {
  std::string binary;                 ///< the shellmpm executable the runs use
  std::string scenes_dir;             ///< where the problems' scenes are (scenes/study)
  std::string output;                 ///< results folder; runs go to OUTPUT/runs/
  std::vector<std::string> problems;  ///< names to run; empty: all
  int threads = 0;                    ///< --threads of every run (0: all cores)
  double budget_seconds = 3600;       ///< no run starts once this much wall time is spent
  std::vector<std::string> sweeps;    ///< sweep names to run ("quality preset"); empty: all
  bool quick = false;                 ///< only the first two settings of each problem's first sweep
  bool keep_runs = false;             ///< keep each run's caches (else removed once measured)
  std::function<void(const std::string&)> log;  ///< progress lines
};

/// One setting of one sweep, run (or not) and measured.
struct StudyRun {
  std::string sweep, label;
  std::vector<std::string> overrides;
  double h = 0;
  std::string status = "skipped";  ///< ok | doubtful | failed | skipped
  std::string note;                ///< why it failed or was skipped
  double value = std::numeric_limits<double>::quiet_NaN();
  double reference = std::numeric_limits<double>::quiet_NaN();
  /// (value - reference) / |reference| for relative problems, value - reference otherwise.
  double error = std::numeric_limits<double>::quiet_NaN();
  double wall_seconds = 0;
  double simulated_seconds = 0;  ///< 0 for static problems
  double cost = 0;               ///< wall seconds per simulated second; wall seconds when static
  long substeps = 0;
  long particles = 0, shell_points = 0, contact_particles = 0;
  double peak_rss_bytes = 0;
  double dx = 0;         ///< the grid spacing of the run [m]
  bool pareto = false;   ///< on the problem's front of (cost, |error|)
  int reused_from = -1;  ///< index of an identical run it shares (same overrides)
};

struct StudySweepResult {
  std::string name, varied, held;
  bool refinement = false;
  std::vector<int> runs;                       ///< indices into StudyProblemResult::runs
  std::optional<double> fitted_order;          ///< slope of log|error| against log h
  std::optional<Extrapolation> extrapolation;  ///< Richardson, from the three finest
};

struct StudyProblemResult {
  std::string name, title, quantity, unit, reference_source;
  bool relative_error = true;
  std::vector<StudyRun> runs;
  std::vector<StudySweepResult> sweeps;
};

struct StudyResults {
  std::vector<StudyProblemResult> problems;
  double wall_seconds = 0;
  int threads = 0;
  double budget_seconds = 0;
  bool quick = false;
};

/// Runs the study. Every setting's scene is read (with its overrides) before anything runs,
/// so a bad key or value stops it at once with the scene reader's message.
/// @throws UserError for an unknown problem name or a setting the scene reader refuses.
StudyResults run_study(const StudyOptions& opt);

/// Marks the runs on the front of (cost, |error|): no other run is both cheaper (or as
/// cheap) and more accurate (or as accurate), with one of the two strictly.
void mark_pareto_front(std::vector<StudyRun>& runs);

}  // namespace shellmpm

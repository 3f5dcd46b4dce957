// `shellmpm study`: runs the reference problems (study/), writes results.json,
// results.csv, summary.md and the plots, and prints where they are.
#include <cstdio>
#include <filesystem>

#include "app/commands.h"
#include "farm/subprocess.h"
#include "study/child_run.h"
#include "study/plots.h"
#include "study/study_report.h"
#include "study/study_runner.h"

namespace shellmpm {

int study_command(const StudyArgs& a) {
  StudyOptions o;
  o.binary = self_executable();
  o.scenes_dir = a.scenes.empty() ? std::string(SHELLMPM_SOURCE_DIR) + "/scenes/study" : a.scenes;
  o.output = a.output;
  o.problems = a.suites;
  o.sweeps = a.sweeps;
  o.threads = a.threads;
  o.budget_seconds = a.budget;
  o.quick = a.quick;
  o.keep_runs = a.keep_runs;
  if (a.verbosity != Verbosity::Quiet) o.log = print_line;
  std::filesystem::create_directories(o.output);
  const StudyResults r = run_study(o);
  write_study_report(r, o.output);
  int failed = 0;
  for (const StudyProblemResult& p : r.problems)
    for (const StudyRun& run : p.runs) failed += run.status == "failed";
  if (a.plots) {
    const std::string script = a.plot_script.empty()
                                   ? std::string(SHELLMPM_SOURCE_DIR) + "/tools/plot_study.py"
                                   : a.plot_script;
    const PlotOutcome po = make_study_plots(script, o.output + "/results.json", o.output);
    std::printf("%s\n", po.message.c_str());
  }
  std::printf("study: %.0f s, results in %s (results.json, results.csv, summary.md)%s\n",
              r.wall_seconds, o.output.c_str(),
              failed > 0 ? (", " + std::to_string(failed) + " run(s) failed").c_str() : "");
  return failed > 0 ? kExitSimulation : kExitOk;
}

}  // namespace shellmpm

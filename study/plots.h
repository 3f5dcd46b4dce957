// The study's figures: tools/plot_study.py (matplotlib) turns results.json into a Pareto
// plot and a convergence plot per problem. Plotting is optional: without Python or
// matplotlib the study still writes its JSON, CSV and tables, and says why there are no
// plots.
#pragma once
#include <string>

namespace shellmpm {

struct PlotOutcome {
  bool made = false;
  std::string message;  ///< what was written, or why nothing was
};

/// Runs `script results_json outdir` with the first Python that imports matplotlib:
/// $SHELLMPM_PYTHON, else /usr/bin/python3 (Debian's python3-matplotlib), else python3 on PATH.
PlotOutcome make_study_plots(const std::string& script, const std::string& results_json,
                             const std::string& outdir);

}  // namespace shellmpm

#include "study/plots.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <vector>

#include "study/child_run.h"

namespace shellmpm {

namespace {

/// The candidate interpreters, in order of preference.
std::vector<std::string> pythons() {
  std::vector<std::string> c;
  if (const char* env = std::getenv("SHELLMPM_PYTHON"); env != nullptr && *env != '\0')
    c.push_back(env);
  if (::access("/usr/bin/python3", X_OK) == 0) c.push_back("/usr/bin/python3");
  c.push_back("python3");
  return c;
}

}  // namespace

PlotOutcome make_study_plots(const std::string& script, const std::string& results_json,
                             const std::string& outdir) {
  PlotOutcome out;
  if (!std::filesystem::exists(script)) {
    out.message = "plots skipped: " + script + " not found";
    return out;
  }
  const std::string log = outdir + "/plots.log";
  for (const std::string& py : pythons()) {
    const ChildRunResult probe = run_process({py, "-c", "import matplotlib"}, log);
    if (probe.exit_code != 0) continue;
    const ChildRunResult r = run_process({py, script, results_json, outdir}, log);
    if (r.exit_code != 0) {
      out.message = "plots failed (" + py + " " + script + ", exit " + std::to_string(r.exit_code) +
                    "): " + r.log_tail;
      return out;
    }
    out.made = true;
    out.message = "plots: " + r.log_tail;
    std::error_code ec;
    std::filesystem::remove(log, ec);
    return out;
  }
  std::error_code ec;
  std::filesystem::remove(log, ec);
  out.message =
      "plots skipped: no Python with matplotlib (Debian: apt-get install python3-matplotlib; "
      "or set SHELLMPM_PYTHON); results.json, results.csv and summary.md are written";
  return out;
}

}  // namespace shellmpm

// `shellmpm converge SCENE --vary KEY=V1,V2,V3 --measure QUANTITY`: the user's shot at
// several settings, the quantity per setting, its observed order, a Richardson estimate
// and what each setting cost (study/convergence.h).
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "app/commands.h"
#include "farm/subprocess.h"
#include "io/atomic_file.h"
#include "study/child_run.h"
#include "study/convergence.h"

namespace shellmpm {

int converge_command(const ConvergeArgs& a) {
  ConvergeOptions o;
  o.binary = self_executable();
  o.scene = a.scene;
  o.overrides = a.overrides;
  for (const std::string& v : a.vary) o.vary.push_back(parse_vary(v));
  o.measure = a.measure;
  o.frames = a.frames;
  o.at_frame = a.at_frame;
  o.spacing = a.spacing;
  o.output = a.output;
  o.threads = a.threads < 0 ? 0 : a.threads;
  o.keep_runs = a.keep_runs;
  if (a.verbosity != Verbosity::Quiet) o.log = print_line;
  std::filesystem::create_directories(o.output);
  const ConvergeResult r = run_convergence(o);
  write_text_atomic(o.output + "/converge.json", convergence_json(r));

  std::printf("\n%-40s %16s %10s %10s %10s\n", "setting", r.quantity.c_str(), "h", "wall s",
              "substeps");
  for (const ConvergeSetting& s : r.settings)
    std::printf("%-40s %16.8g %10.4g %10.2f %10ld\n", s.label.c_str(), s.value, s.h, s.wall_seconds,
                s.substeps);
  if (r.extrapolation) {
    const Extrapolation& e = *r.extrapolation;
    std::printf(
        "observed order %.2f; Richardson estimate %.8g; the finest setting is off by about %.3g "
        "(%.2g%% of the estimate)\n",
        e.order, e.limit, e.error, e.limit != 0 ? 100 * e.error / std::abs(e.limit) : 0.0);
  } else if (r.settings.size() >= 3) {
    std::printf(
        "no order: the values do not change monotonically with the spacing (not yet in the "
        "asymptotic range, or converged to within noise)\n");
  } else {
    const double d = r.settings.back().value - r.settings.front().value;
    std::printf("change between the two settings: %.4g (three settings give an order)\n", d);
  }
  if (r.next_cost_seconds)
    std::printf("the next refinement (h = %.4g) would take about %.0f s\n", *r.next_spacing,
                *r.next_cost_seconds);
  std::printf("wrote %s/converge.json\n", o.output.c_str());
  return kExitOk;
}

}  // namespace shellmpm

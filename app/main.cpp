// shellmpm: command line entry. Parses arguments and hands over to a subcommand.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "app/batch_command.h"
#include "app/commands.h"
#include "io/user_error.h"
#include "sim/core/check.h"
#include "sim/core/lsan_suppressions.h"
#include "sim/scene/scene_words.h"
#include "sim/solver/solver.h"

namespace {

using namespace shellmpm;

void add_common(CLI::App* cmd, CommonArgs& a) {
  cmd->add_option("SCENE", a.scene, "scene file (YAML or JSON)")->required();
  cmd->add_option("--set", a.overrides, "override a scene key: key.path=value (repeatable)")
      ->take_all()
      ->allow_extra_args(false);
  cmd->add_option("--threads", a.threads, "worker threads (0 = all cores; default: scene)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option_function<std::string>(
         "--quality", [&a](const std::string& q) { a.overrides.push_back("shot.quality=" + q); },
         "accuracy preset: draft, preview, production or final (as shot.quality)")
      ->check(CLI::IsMember(words_of<Quality>()));
  cmd->add_flag_callback(
      "--quiet,-q", [&a] { a.verbosity = Verbosity::Quiet; }, "errors only");
  cmd->add_flag_callback(
      "--verbose,-v", [&a] { a.verbosity = Verbosity::Verbose; },
      "per-frame stage timings and energies");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"shellmpm: thin shells and MPM materials with frictional contact"};
  app.set_version_flag("--version", std::string("shellmpm ") + SHELLMPM_VERSION);
  app.require_subcommand(1);

  RunArgs run;
  CLI::App* run_cmd = app.add_subcommand("run", "simulate a scene and write its caches");
  add_common(run_cmd, run);
  run_cmd->add_option("--frames", run.frames, "frame range A-B (or one frame A)");
  run_cmd->add_option("--output,-o", run.output, "output directory (replaces output.directory)");
  run_cmd->add_flag("--resume", run.resume,
                    "continue from the newest checkpoint in the output directory");
  run_cmd->add_flag("--force", run.force,
                    "run even when the memory estimate exceeds the available memory");
  run_cmd->add_flag("--preview", run.preview,
                    "render each frame to preview.####.png as it is written (see `render`)");

  CommonArgs check;
  CLI::App* check_cmd = app.add_subcommand(
      "check",
      "validate a scene; print its stages, particle and grid counts, memory and time estimates");
  add_common(check_cmd, check);

  RenderArgs render;
  CLI::App* render_cmd = app.add_subcommand(
      "render", "render a run's caches to preview.####.png, a contact sheet and an MP4");
  render_cmd->add_option("OUTDIR", render.outdir, "output directory of a `shellmpm run`")
      ->required();
  render_cmd->add_option("--frames", render.frames,
                         "frame range A-B (or one frame A); default: the run's");
  render_cmd->add_option("--camera", render.camera, "camera name from render.cameras, or auto");
  render_cmd->add_option("--size", render.size, "image size WxH (e.g. 1280x720)");
  render_cmd
      ->add_option("--renderer", render.renderer, "raster (OpenGL, OSMesa) or raytrace (Embree)")
      ->check(CLI::IsMember(words_of<RendererKind>()));
  render_cmd
      ->add_option("--threads", render.threads,
                   "threads for TBB, Embree and llvmpipe (0 = all cores)")
      ->check(CLI::NonNegativeNumber);
  render_cmd->add_option("--scene", render.scene, "scene file to use instead of OUTDIR/run.json");
  render_cmd
      ->add_option("--set", render.overrides, "override a scene key: key.path=value (repeatable)")
      ->take_all()
      ->allow_extra_args(false);
  render_cmd->add_flag_callback(
      "--quiet,-q", [&render] { render.verbosity = Verbosity::Quiet; }, "errors only");
  render_cmd->add_flag_callback(
      "--verbose,-v", [&render] { render.verbosity = Verbosity::Verbose; }, "per-frame timings");

  StudyArgs study;
  CLI::App* study_cmd = app.add_subcommand(
      "study", "the accuracy-vs-time study: reference problems over sweeps of settings");
  study_cmd
      ->add_option("--suite", study.suites,
                   "reference problems to run (names, or all; repeatable; default all)")
      ->take_all();
  study_cmd
      ->add_option("--sweep", study.sweeps,
                   "sweeps to run, by name (e.g. \"quality preset\"; repeatable; default all)")
      ->take_all();
  study_cmd->add_option("--budget", study.budget, "no run starts after this many seconds")
      ->check(CLI::PositiveNumber);
  study_cmd->add_option("--output,-o", study.output, "results folder (default out/study)");
  study_cmd->add_option("--threads", study.threads, "threads of every run (0 = all cores)")
      ->check(CLI::NonNegativeNumber);
  study_cmd->add_flag("--quick", study.quick,
                      "two settings of each problem's first sweep (a smoke test)");
  study_cmd->add_flag("--keep-runs", study.keep_runs, "keep every run's caches");
  study_cmd->add_flag_callback(
      "--no-plots", [&study] { study.plots = false; }, "do not call tools/plot_study.py");
  study_cmd->add_option("--scenes", study.scenes, "folder of the problems' scenes");
  study_cmd->add_option("--plot-script", study.plot_script, "the plotting script");
  study_cmd->add_flag_callback(
      "--quiet,-q", [&study] { study.verbosity = Verbosity::Quiet; }, "errors only");

  ConvergeArgs converge;
  CLI::App* converge_cmd = app.add_subcommand(
      "converge", "a quantity of a shot over refinements: observed order, Richardson estimate");
  add_common(converge_cmd, converge);
  converge_cmd
      ->add_option("--vary", converge.vary,
                   "KEY=V1,V2,V3 (repeatable: keys varied together, as many values each)")
      ->required();
  converge_cmd
      ->add_option(
          "--measure", converge.measure,
          "quantity: shell.NAME.lowest, shell.NAME.centroid.y, bulk.max.x, "
          "stats.kinetic_energy, max:stats.KEY, ... (docs/accuracy.md, \"Convergence for your "
          "own shot\")")
      ->required();
  converge_cmd->add_option("--frames", converge.frames, "frame range A-B of every run");
  converge_cmd->add_option("--at", converge.at_frame, "frame measured (default: the last)")
      ->check(CLI::PositiveNumber);
  converge_cmd->add_option("--h", converge.spacing, "spacing of each setting (default: inferred)")
      ->delimiter(',');
  converge_cmd->add_option("--output,-o", converge.output,
                           "folder of the runs (default out/converge)");
  converge_cmd->add_flag("--keep-runs", converge.keep_runs, "keep every run's caches");

  BatchArgs batch;
  CLI::App* batch_cmd = add_batch_subcommand(app, batch);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? kExitOk : kExitUserError;
  }
  try {
    if (*run_cmd) return run_command(run);
    if (*check_cmd) return check_command(check);
    if (*render_cmd) return render_command(render);
    if (*study_cmd) return study_command(study);
    if (*converge_cmd) return converge_command(converge);
    if (*batch_cmd) return batch_command(*batch_cmd, batch);
  } catch (const UserError& e) {
    std::fprintf(stderr, "\nerror: %s\n", e.what());
    return kExitUserError;
  } catch (const SimulationError& e) {
    std::fprintf(stderr, "\nsimulation stopped: %s\n", e.what());
    return kExitSimulation;
  } catch (const InvariantError& e) {
    std::fprintf(stderr, "\n%s\nthis is a bug in shellmpm; please report it with the scene file\n",
                 e.what());
    return kExitInternal;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "\nerror: %s\n", e.what());
    return kExitSimulation;
  }
  return kExitOk;
}

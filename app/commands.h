// The `shellmpm` subcommands. Each returns the process exit code.
#pragma once
#include <string>
#include <vector>

#include "app/progress.h"

namespace shellmpm {

/// Exit codes (documented in the README).
enum ExitCode : int {
  kExitOk = 0,
  kExitSimulation = 1,  ///< the simulation could not go on (e.g. dt below dt_min), I/O failure
  kExitUserError = 2,   ///< bad scene file, mesh, flag or value
  kExitInternal = 3,    ///< a bug in shellmpm (internal check failed)
};

/// What `check` and `run` say about shot.shell_fields_in_solve.
inline constexpr const char* kFieldsInSolveWarning =
    "shot.shell_fields_in_solve is experimental: on the can on sand at 1/2400 s steps it "
    "blew up when the plate lifted off (docs/implicit.md); the energy audit reports such a "
    "frame (stats.json: energy; shot.on_energy_gain: stop ends the run there)";

struct CommonArgs {
  std::string scene;
  std::vector<std::string> overrides;  ///< --set key=value
  int threads = -1;                    ///< -1: from the scene
  Verbosity verbosity = Verbosity::Normal;
};

struct RunArgs : CommonArgs {
  std::string frames;  ///< "A-B" or "A"
  std::string output;  ///< replaces output.directory
  bool resume = false;
  bool preview = false;  ///< render each frame as it is written (also render.preview)
  bool force = false;    ///< run even when the memory estimate exceeds the available memory
};

/// `shellmpm render OUTDIR`: preview images of a run's caches.
struct RenderArgs {
  std::string outdir;
  std::string frames;                  ///< "A-B" or "A"; default: the frames the run wrote
  std::string camera;                  ///< replaces render.camera
  std::string size;                    ///< "WxH"; replaces render.size
  std::string renderer;                ///< raster | raytrace; replaces render.renderer
  std::string scene;                   ///< a scene file to use instead of OUTDIR/run.json
  std::vector<std::string> overrides;  ///< --set, after the run's own
  int threads = -1;                    ///< -1: from the scene
  Verbosity verbosity = Verbosity::Normal;
};

/// `shellmpm study`: the accuracy-vs-time study over the reference problems.
struct StudyArgs {
  std::vector<std::string> suites;  ///< problem names, or "all"
  std::vector<std::string> sweeps;  ///< sweep names to run; empty: all
  double budget = 3600;             ///< [s]
  std::string output = "out/study";
  int threads = 0;
  bool quick = false;      ///< two settings of each problem's first sweep
  bool keep_runs = false;  ///< keep every run's caches
  bool plots = true;
  std::string scenes;       ///< folder of the problems' scenes; default: the source tree's
  std::string plot_script;  ///< default: the source tree's tools/plot_study.py
  Verbosity verbosity = Verbosity::Normal;
};

/// `shellmpm converge SCENE`: a quantity of the user's shot over refinements of a knob.
struct ConvergeArgs : CommonArgs {
  std::vector<std::string> vary;  ///< KEY=V1,V2,... (repeatable: keys moved together)
  std::string measure;
  std::string frames;
  int at_frame = 0;
  std::vector<double> spacing;  ///< --h
  std::string output = "out/converge";
  bool keep_runs = false;
};

int run_command(const RunArgs& a);
int study_command(const StudyArgs& a);
int converge_command(const ConvergeArgs& a);
int check_command(const CommonArgs& a);
int render_command(const RenderArgs& a);

}  // namespace shellmpm

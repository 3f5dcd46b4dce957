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

int run_command(const RunArgs& a);
int check_command(const CommonArgs& a);
int render_command(const RenderArgs& a);

}  // namespace shellmpm

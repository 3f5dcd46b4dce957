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
};

int run_command(const RunArgs& a);
int check_command(const CommonArgs& a);

}  // namespace shellmpm

// One `shellmpm run` as a child process, timed and measured from outside: wall-clock
// seconds and peak resident memory (getrusage of the child), its exit status and the tail
// of what it printed. The study and `converge` measure every setting this way, so each
// figure is what a user's own run of that setting costs.
#pragma once
#include <string>
#include <vector>

namespace shellmpm {

struct ChildRunRequest {
  std::string binary;                  ///< the shellmpm executable
  std::string scene;                   ///< scene file
  std::string output;                  ///< output directory (created by the run)
  std::vector<std::string> overrides;  ///< --set values, in order
  int threads = 0;                     ///< --threads (0: all cores)
  std::string frames;                  ///< --frames, empty for the scene's
  std::string log;                     ///< file for the child's stdout and stderr
};

struct ChildRunResult {
  int exit_code = -1;         ///< the child's exit status; 128 + signal when killed
  double wall_seconds = 0;    ///< from start to exit
  double peak_rss_bytes = 0;  ///< ru_maxrss of the child
  std::string log_tail;       ///< the last lines it printed (for error messages)
};

/// Runs `binary run SCENE -o OUTPUT --quiet --threads N [--frames F] --set ...` and waits.
/// @throws std::runtime_error when the process cannot be started.
ChildRunResult run_child(const ChildRunRequest& r);

/// Runs `argv` (argv[0] is the program's path) with stdout and stderr into `log` and stdin
/// from /dev/null, and waits; the result as for run_child. The program is looked up on
/// PATH when argv[0] has no '/'.
/// @throws std::runtime_error when the process cannot be started.
ChildRunResult run_process(const std::vector<std::string>& argv, const std::string& log);

}  // namespace shellmpm

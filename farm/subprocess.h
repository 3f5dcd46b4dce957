// Child processes for the farm: the engines start `shellmpm batch task`, a task starts
// `shellmpm run` or `shellmpm render`, the Slurm engine runs sbatch, scontrol, sinfo and
// squeue. POSIX fork/exec, no shell in between (arguments are never re-parsed).
#pragma once
#include <sys/types.h>

#include <string>
#include <vector>

namespace shellmpm {

/// The path of the running executable (/proc/self/exe): the farm's and the study's
/// children run this same build.
/// @throws std::runtime_error when /proc/self/exe cannot be read.
std::string self_executable();

/// The full path of `name` on PATH (or `name` itself when it holds a '/' and exists), or
/// "" when there is none.
std::string find_program(const std::string& name);

/// Starts argv[0] (a path) with argv. Its stdout and stderr are appended to `log` (created
/// with its folder), or inherited when `log` is empty. SIGTERM and SIGINT are restored to their
/// defaults in the child. With `own_group` it gets a process group of its own (a terminal's Ctrl-C
/// reaches the parent alone, which passes it on).
/// @throws std::system_error when fork fails or the log cannot be opened.
pid_t spawn_process(const std::vector<std::string>& argv, const std::string& log, bool own_group);

/// Waits for `pid`. Returns its exit code, 128 + the signal when a signal ended it, or
/// -1 when `nohang` and it is still running. A failed exec exits 127.
int wait_process(pid_t pid, bool nohang);

struct CommandOutput {
  int code = -1;       ///< exit code (128 + signal when killed; 127 when it could not start)
  std::string output;  ///< stdout and stderr together
};

/// Runs argv to completion, capturing its output; killed (SIGKILL) after `timeout_s`.
CommandOutput run_capture(const std::vector<std::string>& argv, double timeout_s = 60);

/// The short host name (`hostname -s`).
std::string short_hostname();

/// The cores this process may run on (sched_getaffinity), at least 1.
int available_cores();

}  // namespace shellmpm

// Helpers for tests that run the shellmpm binary.
#pragma once
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/support/jelly_scene.h"
#include "tests/support/temp_dir.h"

namespace shellmpm_test {

struct CmdResult {
  int code = -1;
  std::string output;  ///< stdout and stderr together
};

/// Runs `COMMAND` through the shell, capturing output (stdout and stderr) and the exit code.
inline CmdResult run_command(const std::string& command) {
  const std::string cmd = command + " 2>&1";
  CmdResult r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.output.append(buf.data(), n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

/// Runs `shellmpm ARGS` through the shell, capturing output and the exit code. `env`
/// (e.g. "PATH=/nowhere") is put before the command, for that process alone.
inline CmdResult run_shellmpm(const std::string& args, const std::string& env = "") {
  return run_command((env.empty() ? "" : env + " ") + SHELLMPM_BINARY + " " + args);
}

/// Runs `PREFIX shellmpm ARGS` (PREFIX: e.g. "timeout 10 ").
inline CmdResult run_shellmpm_prefixed(const std::string& prefix, const std::string& args) {
  return run_command(prefix + SHELLMPM_BINARY + " " + args);
}

}  // namespace shellmpm_test

// Helpers for tests that run the shellmpm binary.
#pragma once
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/support/temp_dir.h"

namespace shellmpm_test {

/// A tiny bulk scene (two frames of an elastic box at 240 fps); OUT stands for the output
/// directory.
inline const char* const kTinyJellyScene = R"(version: 1
shot:
  frames: [1, 2]
  fps: 240
  dx: 0.05
  domain: {min: [-0.5, 0, -0.5], max: [0.5, 1, 0.5]}
materials:
  - {name: jelly, type: elastic, youngs_modulus: 1.0e4, density: 1000}
sources:
  - {material: jelly, shape: {type: box, min: [-0.1, 0.3, -0.1], max: [0.1, 0.5, 0.1]}}
output:
  directory: OUT
)";

/// kTinyJellyScene with its last frame set to `last_frame` and its output directory to
/// `out`, followed by `extra` (more top-level sections).
inline std::string tiny_jelly_scene(int last_frame, const std::string& out,
                                    const std::string& extra = "") {
  std::string s = kTinyJellyScene;
  s.replace(s.find("frames: [1, 2]"), 14, "frames: [1, " + std::to_string(last_frame) + "]");
  s.replace(s.find("directory: OUT"), 14, "directory: " + out);
  return s + extra;
}

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

inline std::string read_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

}  // namespace shellmpm_test

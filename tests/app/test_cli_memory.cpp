// The memory guard through the command line: check estimates without building the shot
// and warns, run refuses (exit 2, nothing written) when the estimate exceeds the available
// memory and runs with --force; a sheet at the largest resolution checks in a moment. The
// [slow] case holds the estimate against the peak resident size of real runs.
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <regex>

#include "tests/app/cli_harness.h"

extern char** environ;

using namespace shellmpm_test;

namespace {

std::string write_scene(const TempDir& d, std::string text, const std::string& name = "s.yaml") {
  const auto at = text.find("OUT");
  if (at != std::string::npos) text.replace(at, 3, d.file("out"));
  return d.write(name, text);
}

bool has(const CmdResult& r, const std::string& s) {
  return r.output.find(s) != std::string::npos;
}

/// Sets SHELLMPM_AVAILABLE_MEMORY for the scope (the child processes inherit it).
struct Available {
  explicit Available(const char* v) { setenv("SHELLMPM_AVAILABLE_MEMORY", v, 1); }
  ~Available() { unsetenv("SHELLMPM_AVAILABLE_MEMORY"); }
};

/// The "memory: about X UNIT" figure of check, in bytes.
double estimate_of(const CmdResult& check) {
  std::smatch m;
  REQUIRE(std::regex_search(check.output, m, std::regex("memory: about ([0-9.]+) (MiB|GiB)")));
  return std::stod(m[1]) * (m[2] == "GiB" ? 1024.0 * 1024 * 1024 : 1024.0 * 1024);
}

/// Runs shellmpm with `args` and returns its peak resident size [bytes] (wait4's ru_maxrss).
double peak_rss(const std::vector<std::string>& args) {
  std::vector<std::string> all{SHELLMPM_BINARY};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  REQUIRE(posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) == 0);
  int status = 0;
  rusage ru{};
  REQUIRE(wait4(pid, &status, 0, &ru) == pid);
  REQUIRE(WIFEXITED(status));
  REQUIRE(WEXITSTATUS(status) == 0);
  return static_cast<double>(ru.ru_maxrss) * 1024.0;
}

}  // namespace

TEST_CASE("CLI memory: run refuses a scene larger than the available memory",
          "[cli][memory_guard]") {
  TempDir d("cli_memory");
  const std::string s = write_scene(d, kTinyJellyScene);
  {
    Available tiny("1K");  // the scene needs some 100 KiB more than the process holds
    const CmdResult c = run_shellmpm("check " + s);
    INFO(c.output);
    CHECK(c.code == 0);
    CHECK(has(c, "warning: that is"));
    CHECK(has(c, "only 1.00 KiB is available (SHELLMPM_AVAILABLE_MEMORY)"));
    CHECK(has(c, "`shellmpm run` will refuse it"));
    const CmdResult r = run_shellmpm("run " + s + " -q");
    INFO(r.output);
    CHECK(r.code == 2);
    CHECK(has(r, "s.yaml: the run needs about "));
    CHECK(has(r, "only 1.00 KiB is available (SHELLMPM_AVAILABLE_MEMORY)"));
    CHECK(has(r, "--force"));
    CHECK(!std::filesystem::exists(d.file("out")));  // refused before anything is written
    const CmdResult f = run_shellmpm("run " + s + " -q --force");
    INFO(f.output);
    CHECK(f.code == 0);
    CHECK(std::filesystem::exists(d.file("out/stats.json")));
  }
  {
    Available plenty("64G");
    const CmdResult c = run_shellmpm("check " + s);
    CHECK(c.code == 0);
    CHECK(!has(c, "warning"));
    CHECK(run_shellmpm("run " + s + " -q").code == 0);
  }
  {
    Available bad("lots");
    const CmdResult r = run_shellmpm("run " + s + " -q");
    CHECK(r.code == 2);
    CHECK(has(r, "SHELLMPM_AVAILABLE_MEMORY=lots: expected a size"));
  }
}

TEST_CASE("CLI memory: a sheet at the largest resolution checks without building it",
          "[cli][memory_guard]") {
  TempDir d("cli_memory_sheet");
  const std::string s =
      write_scene(d,
                  "version: 1\n"
                  "shot: {dx: 0.01, domain: {min: [-1, -1, -1], max: [1, 1, 1]}}\n"
                  "shell_materials: [{name: cotton, density: 400}]\n"
                  "shells:\n"
                  "  - {name: cloth, material: cotton, geometry: {type: sheet, "
                  "size: [1.6, 1.6], resolution: [2000, 2000]}}\n"
                  "output: {directory: OUT}\n");
  const CmdResult c = run_shellmpm("check " + s);
  INFO(c.output);
  REQUIRE(c.code == 0);
  CHECK(has(c, "shells: 4004001 control points, 8000000 triangles, 24000000 quadrature points"));
  CHECK(has(c, "check does not build a shot this large"));
  CHECK(!has(c, "stages:"));
  // Tens of GiB: more than this test lets it have, so run refuses at once.
  CHECK(estimate_of(c) > 16.0 * 1024 * 1024 * 1024);
  Available some("16G");
  const CmdResult r = run_shellmpm("run " + s + " -q");
  CHECK(r.code == 2);
  CHECK(has(r, "the run needs about "));
}

TEST_CASE("CLI memory: the estimate against the peak resident size of runs",
          "[cli][memory_guard][slow]") {
  TempDir d("cli_memory_rss");
  // Bulk-heavy, shell-heavy, and mixed (two cloths with contact, per-shell fields, a block).
  const std::string head =
      "version: 1\n"
      "shot: {frames: [1, 2], fps: 240, dx: 0.01, domain: {min: [-1, -0.2, -1], max: [1, 1.2, "
      "1]}}\n"
      "output: {directory: OUT, checkpoint_every: 1}\n";
  const std::string bulk =
      "materials: [{name: sand, type: sand, youngs_modulus: 3.5e5, density: 1600}]\n"
      "sources: [{material: sand, shape: {type: sphere, center: [0, 0.4, 0], radius: 0.3}}]\n"
      "colliders: [{shape: {type: plane, point: [0, 0, 0], normal: [0, 1, 0]}}]\n";
  const std::string cloth =
      "shell_materials: [{name: cotton, youngs_modulus: 1e5, density: 400}]\n"
      "shells:\n"
      "  - {name: a, material: cotton, translate: [0, 0.3, 0], geometry: {type: sheet, size: "
      "[1.6, 1.6], resolution: [150, 150]}}\n";
  const std::string second =
      "  - {name: b, material: cotton, translate: [0, 0.1, 0], geometry: {type: sheet, size: "
      "[1.6, 1.6], resolution: [150, 150]}}\n"
      "materials: [{name: jelly, type: elastic}]\n"
      "sources: [{material: jelly, shape: {type: box, min: [-0.2, 0.5, -0.2], max: [0.2, 0.9, "
      "0.2]}}]\n";
  // Implicit sheets (0.5 m, 0.5 mm, clamped at one edge), at sizes the estimate was not
  // calibrated on (32, 64 and 128 elements a side): steel with the factorised
  // preconditioner's LDL^T factor, and a softer sheet with block Jacobi (on steel it takes
  // thousands of CG iterations a step: memory does not depend on E, time does).
  const auto steel = [](const std::string& pre, int n, const std::string& E) {
    const std::string r = std::to_string(n);
    return "version: 1\n"
           "shot: {frames: [1, 2], fps: 24, dx: 0.02, integrator: implicit, "
           "implicit_preconditioner: " +
           pre +
           ", domain: {min: [-1, -1, -1], max: [1, 1, 1]}}\n"
           "output: {directory: OUT}\n"
           "shell_materials: [{name: steel, youngs_modulus: " +
           E +
           ", density: 7850, thickness: 5e-4}]\n"
           "shells:\n"
           "  - {name: s, material: steel, contact: off, geometry: {type: sheet, size: [0.5, "
           "0.5], resolution: [" +
           r + ", " + r + "]}, pins: [{box: {min: [-1, -1, -1], max: [-0.2499, 1, 1]}}]}\n";
  };
  const std::string scenes[] = {head + bulk, head + cloth, head + cloth + second,
                                steel("block_jacobi", 48, "2e8"), steel("factorised", 80, "2e11")};
  int k = 0;
  for (const std::string& text : scenes) {
    const std::string s = write_scene(d, text, "s" + std::to_string(k++) + ".yaml");
    const CmdResult c = run_shellmpm("check " + s);
    INFO(c.output);
    REQUIRE(c.code == 0);
    const double est = estimate_of(c);
    const double rss = peak_rss({"run", s, "-q", "--threads", "1"});
    CAPTURE(est, rss);
    CHECK(est == Approx(rss).epsilon(0.25));
  }
}

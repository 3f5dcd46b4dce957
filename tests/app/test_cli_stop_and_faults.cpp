// The binary under a scheduler's SIGTERM, a user's Ctrl-C and a failing disk:
// SIGTERM/SIGINT finish the frame in progress, write a checkpoint and exit 143/130,
// and --resume then gives the uninterrupted run's results; a write that fails (past
// RLIMIT_FSIZE, as on a full disk) exits 1 naming the file and leaves every file that
// was already there as it was, with no temporary behind.
#include <signal.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>

#include "tests/app/cli_harness.h"
#include "tests/app/cli_process.h"

namespace fs = std::filesystem;
using namespace shellmpm_test;

namespace {

const std::string kJelly = jelly_scene(40, "", "OUT", "  particles: true\n");

std::string make_scene(const TempDir& d) {
  std::string t = kJelly;
  t.replace(t.find("OUT"), 3, d.file("default_out"));
  return d.write("jelly.yaml", t);
}

std::string particles(const std::string& dir, int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "/particles.%04d.ply", frame);
  return read_text(dir + name);
}

nlohmann::json physics_stats(const std::string& path) {
  auto j = nlohmann::json::parse(read_text(path));
  for (auto& f : j["frames"]) f.erase("wall");
  return j["frames"];
}

/// Starts a run, sends `signal` once frame 2 is on disk, and checks the graceful stop:
/// exit 128 + signal, a checkpoint of the last frame written although
/// output.checkpoint_every is 0, a message pointing to --resume, no temporaries; then
/// resumes and compares every frame with the uninterrupted run in `full`.
void stop_and_resume(const TempDir& d, const std::string& scene, const std::string& full,
                     int signal, const std::string& name) {
  const std::string out = d.file(name);
  const Child c =
      spawn_shellmpm({"run", scene, "-q", "--threads", "1", "-o", out}, d.file(name + ".log"));
  REQUIRE(c.pid > 0);
  const bool started = wait_for_file(out + "/particles.0002.ply", 60);
  kill(c.pid, signal);
  const CmdResult r = wait_child(c);
  INFO(r.output);
  REQUIRE(started);
  REQUIRE(r.code == 128 + signal);
  std::smatch m;
  const std::regex re(
      "stopped by (SIG[A-Z]+) after frame ([0-9]+) .*checkpoint '([^']+)' written: "
      "run the same command with --resume to continue");
  REQUIRE(std::regex_search(r.output, m, re));
  CHECK(m[1] == (signal == SIGTERM ? "SIGTERM" : "SIGINT"));
  const int last = std::stoi(m[2]);
  CHECK(last >= 2);
  CHECK(last < 40);
  CHECK(m[3] == out + "/checkpoint." + std::string(4 - std::to_string(last).size(), '0') +
                    std::to_string(last) + ".bin");
  CHECK(fs::exists(std::string(m[3])));
  CHECK(d.temp_files() == 0);
  CHECK(particles(out, last) == particles(full, last));
  CHECK_FALSE(fs::exists(out + "/particles.0040.ply"));

  const CmdResult resumed = run_shellmpm("run " + scene + " -q --resume -o " + out);
  INFO(resumed.output);
  REQUIRE(resumed.code == 0);
  for (int f = 1; f <= 40; ++f) {
    INFO("frame " << f);
    CHECK(particles(out, f) == particles(full, f));
  }
  CHECK(physics_stats(out + "/stats.json").dump() == physics_stats(full + "/stats.json").dump());
}

}  // namespace

TEST_CASE(
    "CLI: SIGTERM and SIGINT stop after the frame with a checkpoint and --resume completes it",
    "[cli][resume][signals]") {
  TempDir d("stop");
  const std::string s = make_scene(d);
  REQUIRE(run_shellmpm("run " + s + " -q -o " + d.file("full")).code == 0);
  REQUIRE(particles(d.file("full"), 40).size() > 1000);
  stop_and_resume(d, s, d.file("full"), SIGTERM, "term");
  stop_and_resume(d, s, d.file("full"), SIGINT, "int");
}

TEST_CASE(
    "CLI: a write that fails (file size limit, like a full disk) exits 1 naming the file "
    "and nothing already written changes",
    "[cli][atomic]") {
  TempDir d("disk_full");
  const std::string s = make_scene(d);
  const std::string out = d.file("o");
  REQUIRE(run_shellmpm("run " + s + " -q --frames 1-3 -o " + out).code == 0);
  const std::string vdb = read_text(out + "/density.0001.vdb"),
                    stats = read_text(out + "/stats.json");
  constexpr std::size_t kLimit = 16 * 1024;  // above run.json, below one density frame
  REQUIRE(vdb.size() > 2 * kLimit);
  REQUIRE(fs::file_size(out + "/run.json") < kLimit);

  const Child c =
      spawn_shellmpm({"run", s, "-q", "--frames", "1-3", "-o", out}, d.file("run.log"), kLimit);
  const CmdResult r = wait_child(c);
  INFO(r.output);
  CHECK(r.code == 1);
  CHECK(r.output.find(out + "/density.0001.vdb") != std::string::npos);
  CHECK(r.output.find("File too large") != std::string::npos);
  CHECK(read_text(out + "/density.0001.vdb") == vdb);
  CHECK(read_text(out + "/stats.json") == stats);
  CHECK(fs::exists(out + "/density.0003.vdb"));
  CHECK(d.temp_files() == 0);

  // Into an empty folder: no truncated frame under its final name.
  const std::string fresh = d.file("fresh");
  const CmdResult r2 = wait_child(spawn_shellmpm({"run", s, "-q", "--frames", "1-3", "-o", fresh},
                                                 d.file("fresh.log"), kLimit));
  INFO(r2.output);
  CHECK(r2.code == 1);
  CHECK_FALSE(fs::exists(fresh + "/density.0001.vdb"));
  CHECK(d.temp_files() == 0);
}

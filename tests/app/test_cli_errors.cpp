// Bad input through the command line: each case gets a clear message naming the
// file, line and key, and exit code 2; nothing already written is touched.
#include <unistd.h>

#include <catch2/catch.hpp>

#include "tests/app/cli_harness.h"

using namespace shellmpm_test;

namespace {

const std::string kGood = jelly_scene(3, "", "OUT");

std::string scene_with(const TempDir& d, std::string text, const std::string& from = "",
                       const std::string& to = "") {
  const auto pos = text.find("OUT");
  text.replace(pos, 3, d.file("out"));
  if (!from.empty()) {
    const auto p = text.find(from);
    REQUIRE(p != std::string::npos);
    text.replace(p, from.size(), to);
  }
  return d.write("scene.yaml", text);
}

void expect_user_error(const CmdResult& r, std::initializer_list<std::string> parts) {
  INFO(r.output);
  REQUIRE(r.code == 2);
  for (const std::string& s : parts) REQUIRE(r.output.find(s) != std::string::npos);
}

}  // namespace

TEST_CASE("CLI: the good scene checks and runs", "[cli]") {
  TempDir d("cli_good");
  const std::string s = scene_with(d, kGood);
  const CmdResult c = run_shellmpm("check " + s);
  INFO(c.output);
  REQUIRE(c.code == 0);
  REQUIRE(c.output.find("stages: bin, p2g, grid, g2p") != std::string::npos);
  const CmdResult r = run_shellmpm("run " + s + " --quiet");
  INFO(r.output);
  REQUIRE(r.code == 0);
  REQUIRE(std::filesystem::exists(d.file("out/density.0003.vdb")));
  REQUIRE(std::filesystem::exists(d.file("out/stats.json")));
  REQUIRE(run_shellmpm("--version").output.find("shellmpm") != std::string::npos);
  REQUIRE(run_shellmpm("run --help").code == 0);
}

TEST_CASE("CLI: bad input gives file, line, key and exit code 2", "[cli]") {
  TempDir d("cli_bad");
  SECTION("missing scene file") {
    expect_user_error(run_shellmpm("run " + d.file("nope.yaml")), {"nope.yaml"});
  }
  SECTION("YAML syntax error") {
    const std::string s = scene_with(d, kGood, "dx: 0.05", "dx: [0.05");
    expect_user_error(run_shellmpm("run " + s), {"scene.yaml:"});
  }
  SECTION("unknown key") {
    const std::string s = scene_with(d, kGood, "dx: 0.05", "dx: 0.05\n  dxx: 1");
    expect_user_error(run_shellmpm("run " + s), {"scene.yaml:5", "dxx"});
  }
  SECTION("wrong type") {
    const std::string s = scene_with(d, kGood, "dx: 0.05", "dx: fine");
    expect_user_error(run_shellmpm("run " + s), {"scene.yaml:4", "shot.dx"});
  }
  SECTION("out of range") {
    const std::string s = scene_with(d, kGood, "poisson_ratio: 0.3", "poisson_ratio: 0.7");
    expect_user_error(run_shellmpm("run " + s), {"scene.yaml:7", "poisson_ratio"});
  }
  SECTION("missing required key") {
    const std::string s = scene_with(d, kGood, "  dx: 0.05\n", "");
    expect_user_error(run_shellmpm("run " + s), {"scene.yaml", "dx"});
  }
  SECTION("unknown material") {
    const std::string s = scene_with(d, kGood, "{material: jelly", "{material: jam");
    expect_user_error(run_shellmpm("run " + s), {"scene.yaml:9", "jam"});
  }
  SECTION("missing mesh file") {
    const std::string s =
        scene_with(d, kGood, "{type: box, min: [-0.1, 0.3, -0.1], max: [0.1, 0.5, 0.1]}",
                   "{type: mesh, path: missing.obj}");
    expect_user_error(run_shellmpm("run " + s), {"scene.yaml:9", "missing.obj"});
  }
  SECTION("corrupt mesh file") {
    d.write("broken.obj", "v 0 0 0\nf 1 2 3 4 5\nthis is not an obj\n");
    const std::string s =
        scene_with(d, kGood, "{type: box, min: [-0.1, 0.3, -0.1], max: [0.1, 0.5, 0.1]}",
                   "{type: mesh, path: broken.obj}");
    expect_user_error(run_shellmpm("run " + s), {"broken.obj"});
  }
  SECTION("source outside the domain") {
    const std::string s = scene_with(d, kGood, "max: [0.1, 0.5, 0.1]", "max: [0.1, 1.5, 0.1]");
    expect_user_error(run_shellmpm("run " + s),
                      {"scene.yaml:9", "sources[0].shape", "outside shot.domain"});
  }
  SECTION("--set with an unknown key") {
    const std::string s = scene_with(d, kGood);
    expect_user_error(run_shellmpm("run " + s + " --set shot.dxx=1"), {"--set shot.dxx=1", "dxx"});
  }
  SECTION("--set with a bad value") {
    const std::string s = scene_with(d, kGood);
    expect_user_error(run_shellmpm("run " + s + " --set shot.dx=-1"),
                      {"--set shot.dx=-1", "shot.dx"});
  }
  SECTION("bad --frames") {
    const std::string s = scene_with(d, kGood);
    expect_user_error(run_shellmpm("run " + s + " --frames 5-2"), {"--frames 5-2"});
  }
  SECTION("bad --threads") {
    const std::string s = scene_with(d, kGood);
    const CmdResult r = run_shellmpm("run " + s + " --threads -3");
    INFO(r.output);
    REQUIRE(r.code == 2);
    REQUIRE(r.output.find("--threads") != std::string::npos);
  }
  SECTION("unknown flag and subcommand") {
    REQUIRE(run_shellmpm("run x.yaml --bogus").code == 2);
    REQUIRE(run_shellmpm("explode").code == 2);
  }
  SECTION("corrupt checkpoint on --resume") {
    const std::string s = scene_with(d, kGood);
    std::filesystem::create_directories(d.file("out"));
    d.write("out/checkpoint.0002.bin", "SHMPMCK1 garbage");
    expect_user_error(run_shellmpm("run " + s + " --resume"), {"checkpoint.0002.bin"});
  }
}

TEST_CASE("CLI: a failed run leaves existing output untouched and no temp files", "[cli]") {
  TempDir d("cli_keep");
  const std::string s = scene_with(d, kGood);
  REQUIRE(run_shellmpm("run " + s + " --quiet").code == 0);
  const std::string before = read_text(d.file("out/density.0002.vdb"));
  const std::string stats = read_text(d.file("out/stats.json"));
  REQUIRE(run_shellmpm("run " + s + " --quiet --set shot.cfl=7").code == 2);
  // dt_min impossible to meet: the simulation stops with exit code 1 after frame 1.
  const CmdResult r =
      run_shellmpm("run " + s + " --quiet --set shot.dt_min=0.005 --set shot.dt_max=0.01 " +
                   "--set materials[0].youngs_modulus=1e9 -o " + d.file("out2"));
  INFO(r.output);
  REQUIRE(r.code == 1);
  REQUIRE(r.output.find("dt_min") != std::string::npos);
  REQUIRE(read_text(d.file("out/density.0002.vdb")) == before);
  REQUIRE(read_text(d.file("out/stats.json")) == stats);
  for (const auto& e : std::filesystem::recursive_directory_iterator(d.path))
    REQUIRE(e.path().string().find(".tmp.") == std::string::npos);
}

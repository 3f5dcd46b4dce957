// shot.integrator implicit through the command line (issue 14): check says what bounds the
// step, run writes the Newton statistics per frame, and shells in contact go into the grid
// solve.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include "tests/app/cli_harness.h"

using namespace shellmpm_test;

namespace {
const std::string kScenes = std::string(SHELLMPM_SOURCE_DIR) + "/scenes/";
}  // namespace

TEST_CASE("CLI implicit: check, run and stats.json", "[cli][implicit]") {
  TempDir d("cli_implicit");
  const std::string set = " --set shot.integrator=implicit";
  const CmdResult c = run_shellmpm("check " + kScenes + "cloth_swing.yaml" + set);
  INFO(c.output);
  REQUIRE(c.code == 0);
  CHECK(c.output.find("integrator: implicit") != std::string::npos);
  CHECK(c.output.find("implicit_shells") != std::string::npos);  // the stage list
  const CmdResult r =
      run_shellmpm("run " + kScenes + "cloth_swing.yaml --frames 1-4 -o " + d.file("out") + set);
  INFO(r.output);
  REQUIRE(r.code == 0);
  const auto j = nlohmann::json::parse(read_text(d.file("out/stats.json")));
  int steps = 0;
  for (const auto& f : j["frames"]) {
    if (f["frame"] == 1) continue;  // the initial state
    const auto& im = f.at("implicit");
    CHECK(im["steps"].get<int>() >= 1);
    CHECK(im["steps"].get<int>() == f["substeps"].get<int>());
    CHECK(im["newton_iterations"].get<int>() >= im["steps"].get<int>());
    CHECK(im["retries"].get<int>() == 0);
    CHECK(im["max_residual"].get<double>() <= 1e-4);  // shot.implicit_tolerance's default
    steps += f["substeps"].get<int>();
  }
  CHECK(steps < 40);  // the explicit run takes hundreds of steps per frame
}

TEST_CASE("CLI implicit: shells in contact are stepped on the implicit grid", "[cli][implicit]") {
  const CmdResult r =
      run_shellmpm("check " + kScenes + "cloth_drape.yaml --set shot.integrator=implicit");
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(r.output.find("implicit_grid") != std::string::npos);
  CHECK(r.output.find("contact_grid") == std::string::npos);  // its forces are in the solve
}

// A frame whose integrity check fails is never silent: `run` warns naming the frame and
// the collider and records it in stats.json; with shot.on_integrity_failure: stop it exits
// 1 after writing that frame's statistics (and not its caches).
#include <catch2/catch.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "tests/app/cli_harness.h"

using namespace shellmpm_test;

namespace {

// Jelly filled half inside a box collider: at frame 1 its lower particles lie up to 2.5
// cells inside the collider (the first step pushes them out).
std::string scene(const TempDir& d, const std::string& mode) {
  const std::string text = std::string(R"(version: 1
shot:
  frames: [1, 3]
  dx: 0.04
  on_integrity_failure: )") +
                           mode + R"(
  domain: {min: [-0.5, 0, -0.5], max: [0.5, 1, 0.5]}
materials:
  - {name: jelly, type: elastic, youngs_modulus: 1.0e4, poisson_ratio: 0.3, density: 1000}
sources:
  - {material: jelly, shape: {type: box, min: [-0.1, 0.2, -0.1], max: [0.1, 0.4, 0.1]}}
colliders:
  - {name: slab, shape: {type: box, min: [-0.3, 0.0, -0.3], max: [0.3, 0.3, 0.3]}}
output:
  directory: )" + d.file("out") +
                           "\n";
  return d.write("scene.yaml", text);
}

}  // namespace

TEST_CASE("CLI: an integrity failure warns with the frame and object and is in stats.json",
          "[cli][integrity]") {
  TempDir d("cli_integrity_warn");
  const CmdResult r = run_shellmpm("run " + scene(d, "warn") + " --quiet");
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(r.output.find("warning: frame 1: ") != std::string::npos);
  CHECK(r.output.find("inside collider 'slab'") != std::string::npos);
  const auto j = nlohmann::json::parse(read_text(d.file("out/stats.json")));
  REQUIRE(j["frames"].size() == 3);
  const auto& f1 = j["frames"][0]["integrity"];
  CHECK(f1["ok"] == false);
  CHECK(f1["collider_penetrations"].get<int>() > 0);
  CHECK(f1["max_collider_depth"].get<double>() > 0.04);
  CHECK(f1["events"][0]["object"] == "slab");
  // The first step puts the jelly back on the slab's surface.
  CHECK(j["frames"][2]["integrity"]["ok"] == true);
}

TEST_CASE("CLI: on_integrity_failure: stop exits 1 and keeps the frame's statistics only",
          "[cli][integrity]") {
  TempDir d("cli_integrity_stop");
  const CmdResult r = run_shellmpm("run " + scene(d, "stop"));
  INFO(r.output);
  CHECK(r.code == 1);
  CHECK(r.output.find("simulation stopped: frame 1: ") != std::string::npos);
  CHECK(r.output.find("(shot.on_integrity_failure: stop)") != std::string::npos);
  const auto j = nlohmann::json::parse(read_text(d.file("out/stats.json")));
  REQUIRE(j["frames"].size() == 1);
  CHECK(j["frames"][0]["integrity"]["ok"] == false);
  CHECK_FALSE(std::filesystem::exists(d.file("out/density.0001.vdb")));
}

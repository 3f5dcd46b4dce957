// The batch file: its expansion into numbered tasks (order, names, folders, overrides),
// and bad input refused at its file, line and key.
#include <catch2/catch.hpp>
#include <string>

#include "farm/batch_file.h"
#include "farm/batch_tasks.h"
#include "io/user_error.h"
#include "tests/farm/farm_fixtures.h"

using namespace shellmpm;
using namespace shellmpm_test;

namespace {

/// The UserError message of parsing `text` as DIR/b.yaml ("" when it parses).
std::string error_of(const TempDir& d, const std::string& text) {
  try {
    parse_batch(text, d.file("b.yaml"));
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("batch file: a product wedge expands in file order, the first key slowest",
          "[farm][batch_file]") {
  TempDir d("farm_expand");
  write_jelly(d, 2);
  const std::string text = R"(version: 1
name: wedge
shots:
  - name: a
    scene: jelly.yaml
    frames: [1, 2]
    set:
      shot.fps: 240
    wedge: w
  - name: b
    scene: jelly.yaml
wedges:
  - name: w
    product:
      materials[0].youngs_modulus: [1e4, 2e4]
      colliders[0].friction: [0.1, 0.5, 0.9]
      sources[0].velocity: [[0, -1, 0]]
)";
  const BatchSpec b = parse_batch(text, d.file("b.yaml"));
  CHECK(b.output == d.file("out/wedge"));
  const std::vector<BatchTask> tasks = expand_tasks(b);
  REQUIRE(tasks.size() == 7);
  CHECK(tasks[0].id() == "a/youngs_modulus-1e4_friction-0.1_velocity-0_-1_0");
  CHECK(tasks[1].id() == "a/youngs_modulus-1e4_friction-0.5_velocity-0_-1_0");
  CHECK(tasks[3].id() == "a/youngs_modulus-2e4_friction-0.1_velocity-0_-1_0");
  CHECK(tasks[5].id() == "a/youngs_modulus-2e4_friction-0.9_velocity-0_-1_0");
  CHECK(tasks[6].id() == "b/base");
  CHECK(tasks[6].wedge_values.empty());
  CHECK_FALSE(tasks[6].frames_from_batch);
  for (int i = 0; i < 7; ++i) CHECK(tasks[i].index == i);
  CHECK(tasks[4].output == d.file("out/wedge/a/youngs_modulus-2e4_friction-0.5_velocity-0_-1_0"));
  // The shot's set first, then the wedge member's; values keep their YAML text.
  const std::vector<std::string> args = run_arguments(tasks[4]);
  const std::vector<std::string> want = {d.file("jelly.yaml"),
                                         "--frames",
                                         "1-2",
                                         "--output",
                                         tasks[4].output,
                                         "--set",
                                         "shot.fps=240",
                                         "--set",
                                         "materials[0].youngs_modulus=2e4",
                                         "--set",
                                         "colliders[0].friction=0.5",
                                         "--set",
                                         "sources[0].velocity=[0, -1, 0]"};
  CHECK(args == want);
  CHECK(values_text(tasks[4]) ==
        "materials[0].youngs_modulus=2e4 colliders[0].friction=0.5 sources[0].velocity=[0, -1, 0]");
  // The same text expands the same way every time (deterministic indices and folders).
  const std::vector<BatchTask> again = expand_tasks(parse_batch(text, d.file("b.yaml")));
  for (int i = 0; i < 7; ++i) CHECK(again[i].output == tasks[i].output);
}

TEST_CASE("batch file: listed sets, inline wedges, preview steps and farm settings",
          "[farm][batch_file]") {
  TempDir d("farm_sets");
  write_jelly(d, 2);
  const BatchSpec b = parse_batch(R"(version: 1
output: /tmp/somewhere
shots:
  - name: s1
    scene: jelly.yaml
    preview: {size: 320x180, renderer: raster}
    wedge:
      sets:
        - name: soft
          set: {shot.fps: 120}
        - name: hard
          set:
            materials[0].youngs_modulus: 3e4
            materials[0].name: "quoted name"
farm:
  slots: 3
  threads: 2
  slurm: {partition: low, time: "00:10:00", mem: 2G, cpus: 2, throttle: 4}
)",
                                  d.file("b.yaml"));
  CHECK(b.name == "b");
  CHECK(b.output == "/tmp/somewhere");
  CHECK(b.farm.slots == 3);
  CHECK(b.farm.threads == 2);
  CHECK(b.farm.slurm.partition == "low");
  CHECK(b.farm.slurm.throttle == 4);
  const std::vector<BatchTask> t = expand_tasks(b);
  REQUIRE(t.size() == 2);
  CHECK(t[0].id() == "s1/soft");
  CHECK(t[1].id() == "s1/hard");
  CHECK(t[1].overrides[1].arg() == "materials[0].name=\"quoted name\"");
  CHECK(t[0].preview.enabled);
  CHECK(t[0].preview.size == "320x180");
}

TEST_CASE("batch file: bad input is refused at its file, line and key", "[farm][batch_file]") {
  TempDir d("farm_bad");
  write_jelly(d, 2);
  const std::string f = d.file("b.yaml");
  const std::string head = "version: 1\nshots:\n  - name: a\n    scene: jelly.yaml\n";
  CHECK(error_of(d, head + "    frobnicate: 3\n") ==
        f + ":5: shots[0].frobnicate: unknown key 'frobnicate' (expected one of: name, scene, "
            "frames, set, wedge, preview)");
  CHECK(error_of(d, head + "    frames: [3, 1]\n") ==
        f + ":5: shots[0].frames: the last frame (1) is before the first (3)");
  CHECK(error_of(d, head + "    wedge: nope\n")
            .find(f + ":3: shots[0].wedge: no wedge named "
                      "'nope'") == 0);
  CHECK(error_of(d, "version: 1\nshots:\n  - name: a\n    scene: missing.yaml\n") ==
        f + ":4: shots[0].scene: no scene file '" + d.file("missing.yaml") + "'");
  CHECK(error_of(d, "version: 1\nshots:\n  - name: ../up\n    scene: jelly.yaml\n")
            .find(f + ":3: shots[0].name: '../up' is not a usable folder name") == 0);
  CHECK(error_of(d, head + head.substr(head.find("  - "))).find("a second shot named 'a'") !=
        std::string::npos);
  CHECK(error_of(d, head + "wedges:\n  - name: w\n    product: {a.b: [1, 1]}\n")
            .find(f + ":6: wedges[0]: two members are both named 'b-1'") == 0);
  CHECK(error_of(d, head + "wedges:\n  - name: w\n    product: {a.b: [1]}\n    sets: []\n")
            .find("needs exactly one of 'sets'") != std::string::npos);
  CHECK(error_of(d, head + "farm:\n  slurm:\n    signal_seconds: 0\n") ==
        f + ":7: farm.slurm.signal_seconds: must be between 1 and 1000000, got 0");
  CHECK(error_of(d, "shots:\n  - name: a\n    scene: jelly.yaml\n") ==
        f + ":1: version: missing (write 'version: 1' first)");
  CHECK(error_of(d, head + "    preview: {size: big}\n") ==
        f + ":5: shots[0].preview.size: expected WIDTHxHEIGHT (e.g. 640x360), got 'big'");
}

TEST_CASE("batch file: a bad override is reported at its line in the batch file",
          "[farm][batch_file]") {
  TempDir d("farm_bad_set");
  write_jelly(d, 2);
  const std::string f = d.file("b.yaml");
  const BatchSpec b = parse_batch(
      "version: 1\nshots:\n  - name: a\n    scene: jelly.yaml\n    wedge: w\nwedges:\n"
      "  - name: w\n    product:\n      materials[0].density: [1000, -5]\n",
      f);
  std::vector<BatchTask> tasks = expand_tasks(b);
  REQUIRE(tasks.size() == 2);
  try {
    resolve_frames(tasks);
    FAIL("a negative density was accepted");
  } catch (const UserError& e) {
    const std::string what = e.what();
    INFO(what);
    CHECK(what.find(f + ":9: wedges[0].product.materials[0].density[1]: ") == 0);
    CHECK(what.find("(task 1, a/density--5)") != std::string::npos);
  }
}

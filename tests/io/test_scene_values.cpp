// Tests of the reader's value bounds (issue 12): values that do not fit float or make the
// state degenerate, timing that could never advance, output file names, invalid UTF-8 and
// --set values that YAML reads as syntax. Each error names the file, the line and the key.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "io/scene_reader.h"

using namespace shellmpm;

namespace {

// Lines 1-4; cases append from line 5.
const std::string kHead =
    "version: 1\n"
    "shot:\n"
    "  domain: {min: [-1, -1, -1], max: [1, 1, 1]}\n"
    "  dx: 0.1\n";

// A shell scene from line 5: material on line 6, shell on lines 8-10.
std::string shell_scene(const std::string& material_extra, const std::string& shell_extra) {
  return kHead +
         "shell_materials:\n"  // 5
         "  - {name: cloth" +
         material_extra +
         "}\n"                                                           // 6
         "shells:\n"                                                     // 7
         "  - material: cloth\n"                                         // 8
         "    geometry: {type: sphere, radius: 0.3, subdivisions: 1}\n"  // 9
         + shell_extra;                                                  // 10...
}

UserError error_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    parse_scene(text, "scenes/v.yaml", overrides);
  } catch (const UserError& e) {
    return e;
  }
  FAIL("expected a UserError for\n" << text);
  throw std::logic_error("unreachable");
}

void expect(const std::string& text, int line, const std::string& key,
            const std::vector<std::string>& parts, const std::vector<std::string>& ov = {}) {
  const UserError e = error_of(text, ov);
  const std::string what = e.what();
  CAPTURE(text, what);
  CHECK(e.file == (ov.empty() ? "scenes/v.yaml" : "--set " + ov.back()));
  CHECK(e.line == line);
  CHECK(e.key == key);
  for (const std::string& p : parts) CHECK(what.find(p) != std::string::npos);
}

}  // namespace

TEST_CASE("scene values: what overflows float is refused at its key", "[scene][values]") {
  const std::string ok = shell_scene("", "");
  REQUIRE_NOTHROW(parse_scene(ok, "scenes/v.yaml"));
  SECTION("a thickness past 1 m (E t^3 overflows float at 1e30)") {
    expect(ok, 0, "shell_materials[0].thickness", {"must be in [1e-7, 1], got 1e30"},
           {"shell_materials[0].thickness=1e30"});
  }
  SECTION("a translation past the position range") {
    expect(ok, 0, "shells[0].translate",
           {"y = -3.5e38", "2^17 = 131072 cells of dx = 0.1 m (13107.2 m)"},
           {"shells[0].translate=[0,-3.5e38,0]"});
    expect(shell_scene("", "    translate: [2e4, 0, 0]\n"), 10, "shells[0].translate",
           {"x = 20000"});
  }
  SECTION("a shell thicker than its radius") {
    expect(shell_scene(", thickness: 0.5", ""), 9, "shells[0].geometry.radius",
           {"radius 0.3 m", "thickness 0.5 m", "'cloth'"});
    expect(shell_scene(", thickness: 0.2", "    scale: 0.5\n"), 9, "shells[0].geometry.radius",
           {"radius 0.15 m"});
  }
  SECTION("moduli, densities and speeds out of their physical range") {
    expect(ok, 0, "shell_materials[0].youngs_modulus", {"[1, 1e12]"},
           {"shell_materials[0].youngs_modulus=1e300"});
    expect(ok, 0, "shell_materials[0].density", {"[0.1, 100000]"},
           {"shell_materials[0].density=1e-300"});
    expect(ok, 0, "shells[0].velocity[1]", {"[-100000, 100000]", "got -1e30"},
           {"shells[0].velocity=[0,-1e30,0]"});
    expect(ok, 0, "shot.gravity[1]", {"got -1e38"}, {"shot.gravity=[0,-1e38,0]"});
    expect(ok, 0, "shells[0].scale", {"[1e-6, 1e6]"}, {"shells[0].scale=1e-300"});
  }
  SECTION("the stiffest modulus of a bulk material") {
    // E (1 - nu) / ((1 + nu) (1 - 2 nu)): 17 E at nu = 0.49, 167 E at 0.499.
    const std::string mat = kHead +
                            "materials:\n  - {name: m, type: elastic, youngs_modulus: "
                            "1e12, poisson_ratio: 0.49}\n";
    REQUIRE_NOTHROW(parse_scene(mat, "scenes/v.yaml"));
    expect(mat, 0, "materials[0].poisson_ratio", {"is 1.67e14 Pa", "at most 1e14"},
           {"materials[0].poisson_ratio=0.499"});
    // nu close to 1/2 makes even a soft material that stiff.
    expect(mat, 0, "materials[0].poisson_ratio", {"at most 1e14"},
           {"materials[0].youngs_modulus=1e6", "materials[0].poisson_ratio=0.499999999"});
    const std::string snow = kHead +
                             "materials:\n  - {name: s, type: snow, hardening: 100, "
                             "critical_compression: 0.5}\n";
    expect(snow, 6, "materials[0].hardening", {"hardening factor", "at most 1e14"});
  }
}

TEST_CASE("scene values: the domain and colliders stay within the position range",
          "[scene][values]") {
  // 2^17 cells of 0.1 m = 13107.2 m.
  expect(kHead, 0, "shot.domain.min[0]", {"x = -20000", "131072 cells"},
         {"shot.domain.min=[-2e4,-1,-1]"});
  const std::string coll = kHead +
                           "colliders:\n  - {shape: {type: sphere, center: [0, 0, 0], "
                           "radius: 1e38}}\n";
  expect(coll, 6, "colliders[0].shape", {"the collider reaches", "-1e38"});
  const std::string plane = kHead +
                            "colliders:\n  - {shape: {type: plane, point: [0, 1e6, 0], "
                            "normal: [0, 1, 0]}}\n";
  expect(plane, 6, "colliders[0].shape.point", {"the plane's point"});
  const std::string keys = kHead +
                           "colliders:\n"
                           "  - shape: {type: sphere, center: [0, 0, 0], radius: 0.1}\n"
                           "    keyframes:\n"
                           "      - {time: 0}\n"
                           "      - {time: 1, translate: [0, -3.5e38, 0]}\n";
  expect(keys, 9, "colliders[0].keyframes[1].translate", {"the translation reaches y"});
}

TEST_CASE("scene values: timing that could never advance is refused", "[scene][values]") {
  expect(kHead, 0, "shot.fps", {"[0.01, 100000]", "got 1e-300"}, {"shot.fps=1e-300"});
  expect(kHead, 0, "shot.dt_min", {">= 1e-9"}, {"shot.dt_min=1e-301"});
  // dt_max below the smallest dt_min cannot be reached: dt_min names the problem.
  expect(kHead, 0, "shot.dt_min", {">= 1e-9"}, {"shot.dt_max=1e-300", "shot.dt_min=1e-301"});
  // A long frame with a tiny dt_min: up to 1 / (fps dt_min) steps.
  expect(kHead + "  fps: 0.02\n", 5, "shot.fps", {"5e7 steps", "at most 1e7", "raise shot.fps"});
  expect(kHead + "  dt_min: 1e-9\n", 5, "shot.dt_min", {"41666667 steps"});
  REQUIRE_NOTHROW(parse_scene(kHead + "  fps: 0.2\n  dt_min: 1e-6\n", "scenes/v.yaml"));
}

TEST_CASE("scene values: output names are files inside output.directory", "[scene][values]") {
  REQUIRE_NOTHROW(parse_scene(
      kHead, "v.yaml",
      {"output.stats=sub/dir/stats.json", "output.density_pattern=vdb/density.####.vdb"}));
  expect(kHead, 0, "output.stats", {"relative to output.directory"},
         {"output.stats=/tmp/stats.json"});
  expect(kHead, 0, "output.stats", {"must end in a file name"}, {"output.stats=sub/"});
  expect(kHead + "output:\n  density_pattern: \"f####/density.vdb\"\n", 6, "output.density_pattern",
         {"must be in the file name, not in a folder"});
  expect(kHead, 0, "output.voxel_size", {"between dx/8 and 16 dx", "0.0125 .. 1.6"},
         {"output.voxel_size=1e-300"});
}

TEST_CASE("scene values: invalid UTF-8 is refused at its line", "[scene][values]") {
  const std::string latin1 = kHead + "# caf\xe9 cr\xe8me\n  fps: 24\n";
  const UserError e = error_of(latin1);
  const std::string what = e.what();
  CAPTURE(what);
  CHECK(e.line == 5);
  CHECK(what.find("not valid UTF-8: byte 0xE9 at column 6") != std::string::npos);
  CHECK(what.find("the key is not known") != std::string::npos);
  // Valid multi-byte text (names, comments) is accepted.
  REQUIRE_NOTHROW(parse_scene(kHead + "# caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80\n", "v.yaml"));
  // Overlong forms and surrogates are not UTF-8.
  CHECK(error_of(kHead + "# \xc0\xaf\n").line == 5);
  CHECK(error_of(kHead + "# \xed\xa0\x80\n").line == 5);
  // An override: named with its key.
  const UserError o = error_of(kHead, {"output.directory=caf\xe9"});
  CHECK(o.key == "output.directory");
  CHECK(std::string(o.what()).find("not valid UTF-8") != std::string::npos);
}

TEST_CASE("scene values: --set values that YAML reads as syntax say how to quote",
          "[scene][values]") {
  SECTION("'{' starts a flow mapping") {
    const std::string ov = "output.shell_pattern={name}.####.ply";
    expect(kHead, 0, "output.shell_pattern",
           {"'{' starts a YAML flow mapping", "--set 'output.shell_pattern=\"{name}.####.ply\"'"},
           {ov});
    // The suggested form reads.
    const Scene s = parse_scene(kHead, "v.yaml", {"output.shell_pattern=\"{name}.####.ply\""});
    CHECK(s.output.shell_pattern == "{name}.####.ply");
  }
  SECTION("'#' starts a comment") {
    expect(kHead, 0, "output.density_pattern", {"'#' at the start starts a YAML comment"},
           {"output.density_pattern=####.vdb"});
    expect(kHead, 0, "output.stats", {"the rest is a comment", "' #' starts a YAML comment"},
           {"output.stats=stats #1.json"});
  }
  SECTION("'*' is an alias; a quote in the value is escaped in the suggestion") {
    expect(kHead, 0, "output.directory", {"'*' starts a YAML alias"}, {"output.directory=*shots"});
    expect(kHead, 0, "output.directory", {"--set 'output.directory=\"{a\\\"b}\"'"},
           {"output.directory={a\"b}"});
  }
  SECTION("numbers and lists are unaffected") {
    CHECK(parse_scene(kHead, "v.yaml", {"shot.gravity=[0, -1, 0]"}).shot.gravity.y() == -1);
    expect(kHead, 0, "shot.dx", {"YAML syntax error"}, {"shot.dx=[0.1"});
  }
}

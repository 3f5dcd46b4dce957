// io/scene_bounds: sources and shells inside the domain, shells resolvable in float, mesh
// colliders within the position range; each error at the file, line and key.
#include <catch2/catch.hpp>

#include <string>

#include "io/mesh_sdf.h"
#include "io/scene_bounds.h"
#include "io/scene_reader.h"
#include "io/shell_assets.h"
#include "io/user_error.h"

using namespace shellmpm;

namespace {

const std::string kPath = std::string(SHELLMPM_SOURCE_DIR) + "/scenes/bounds.yaml";
const std::string kAssets = std::string(SHELLMPM_SOURCE_DIR) + "/scenes/assets/";

// Lines 1-5.
const std::string kHead =
    "version: 1\n"
    "shot:\n"
    "  dx: 0.05\n"
    "  domain: {min: [-1, 0, -1], max: [1, 2, 1]}\n"
    "shell_materials: [{name: cloth}]\n";

void check(const std::string& text) {
  Scene s = parse_scene(text, kPath);
  load_scene_assets(s);
  load_shell_meshes(s);
  check_scene_bounds(s);
}

void expect(const std::string& text, int line, const std::string& key,
            const std::vector<std::string>& parts) {
  try {
    check(text);
  } catch (const UserError& e) {
    const std::string what = e.what();
    CAPTURE(text, what);
    CHECK(e.file == kPath);
    CHECK(e.line == line);
    CHECK(e.key == key);
    for (const std::string& p : parts) CHECK(what.find(p) != std::string::npos);
    return;
  }
  FAIL("expected a UserError for\n" << text);
}

}  // namespace

TEST_CASE("scene bounds: sources one cell inside the domain", "[scene][values]") {
  const std::string src =
      "materials: [{name: m, type: elastic}]\n"                          // 6
      "sources:\n"                                                       // 7
      "  - material: m\n"                                                // 8
      "    shape: {type: sphere, center: [0, 1, 0], radius: RADIUS}\n";  // 9
  auto with = [&](const std::string& r) {
    std::string t = kHead + src;
    t.replace(t.find("RADIUS"), 6, r);
    return t;
  };
  CHECK_NOTHROW(check(with("0.9")));
  // The sphere's bounds reach past the domain less a cell, but its particles do not: the
  // lattice points decide.
  CHECK_NOTHROW(check(with("0.951")));
  expect(with("1.2"), 9, "sources[0].shape", {"source reaches outside shot.domain"});
  expect(with("1e30"), 9, "sources[0].shape", {"source reaches outside shot.domain"});
}

TEST_CASE("scene bounds: shells inside the domain and resolvable in float", "[scene][values]") {
  const std::string shell =
      "shells:\n"                                                          // 6
      "  - material: cloth\n"                                              // 7
      "    geometry: {type: sheet, size: [1, 1], resolution: [10, 10]}\n"  // 8
      "    contact: CONTACT\n"                                             // 9
      "    translate: TRANSLATE\n";                                        // 10
  auto with = [&](const std::string& contact, const std::string& t) {
    std::string s = kHead + shell;
    s.replace(s.find("CONTACT"), 7, contact);
    s.replace(s.find("TRANSLATE"), 9, t);
    return s;
  };
  CHECK_NOTHROW(check(with("on", "[0, 1, 0]")));
  // With contact the shell lives on the grid: one cell inside the domain.
  expect(with("on", "[0.5, 1, 0]"), 10, "shells[0].translate",
         {"outside shot.domain less one cell", "(1, 1,"});
  // Without, anywhere in the position range (2^17 cells of 5 cm = 6553.6 m).
  CHECK_NOTHROW(check(with("off", "[0.5, 1, 0]")));
  CHECK_NOTHROW(check(with("off", "[500, 1, 0]")));
  // At 6000 m float steps are 0.5 mm: 10 cm edges span 200 of them, fewer than 256.
  expect(with("off", "[6000, 1, 0]"), 10, "shells[0].translate",
         {"shortest rest edge, 0.1 m", "fewer than 256 float steps", "towards the origin"});
  expect(with("off", "[6600, 1, 0]"), 10, "shells[0].translate",
         {"the translation reaches x = 6600 m", "more than 2^17 = 131072 cells"});
}

TEST_CASE("scene bounds: mesh colliders within the position range", "[scene][values]") {
  const std::string coll = kHead +
                           "colliders:\n"                      // 6
                           "  - shape: {type: mesh, path: " +  // 7
                           kAssets +
                           "bowl.obj, translate: [X, 0, 0]}\n";
  auto with = [&](const std::string& x) {
    std::string s = coll;
    s.replace(s.find("[X,"), 3, "[" + x + ",");
    return s;
  };
  CHECK_NOTHROW(check(with("0")));
  expect(with("1e4"), 7, "colliders[0].shape.path",
         {"the mesh collider reaches (", "more than 2^17 cells"});
}

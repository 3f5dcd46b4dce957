// The schema binds each key to the field it fills (io/scene_schema.h): every key that is not
// a block, a name or a reference is bound, and every bound default equals the default
// member value of its struct, so a scene that leaves a key out and a Scene built in code
// agree.
#include <catch2/catch.hpp>
#include <set>
#include <string>
#include <typeindex>

#include "io/scene_reader.h"
#include "sim/scene/scene_words.h"

using namespace shellmpm;

namespace {

bool is_block(KeyType t) {
  return t == KeyType::Map || t == KeyType::List || t == KeyType::Shape;
}

const char* const kScene = R"(version: 1
shot:
  domain: {min: [-1, -1, -1], max: [1, 1, 1]}
  dx: 0.02
materials:
  - {name: e, type: elastic}
  - {name: s, type: sand}
  - {name: n, type: snow}
sources:
  - {material: e, shape: {type: box, min: [0, 0, 0], max: [0.2, 0.2, 0.2]}}
colliders:
  - shape: {type: plane, point: [0, -0.9, 0], normal: [0, 1, 0]}
    keyframes: [{time: 0}]
shell_materials:
  - {name: c}
shells:
  - {name: a, material: c, geometry: {type: sheet}, pins: [{indices: [0]}]}
  - {name: b, material: c, geometry: {type: cylinder}}
  - {name: d, material: c, geometry: {type: sphere}}
render:
  cameras: [{name: cam, position: [0, 1, 3], target: [0, 0, 0]}]
)";

/// A row's default compared on one read object against a default-constructed one.
template <class S>
bool same_as_default(const KeySpec& row, const S& read) {
  const S fresh{};
  return row.binding->same(&read, &fresh);
}

}  // namespace

TEST_CASE("schema: every key but blocks, names and references is bound to its field", "[scene]") {
  // Read by hand, each for a reason: the version first, names (defaults by index,
  // uniqueness), references by name, pins' selectors, keyframes' time-or-frame, paths
  // resolved against the scene file, the shell pattern's default from the format, the
  // camera checked against the cameras.
  const std::set<std::string> by_hand = {"version",
                                         "sources[].name",
                                         "sources[].material",
                                         "colliders[].name",
                                         "colliders[].keyframes[].time",
                                         "colliders[].keyframes[].frame",
                                         "shells[].name",
                                         "shells[].material",
                                         "shells[].pins[].indices",
                                         "shells[].pins[].group",
                                         "shells[].pins[].keyframes[].time",
                                         "shells[].pins[].keyframes[].frame",
                                         "shells[].geometry.path",
                                         "output.shell_pattern",
                                         "render.camera",
                                         "shape.path"};
  for (const KeySpec& s : scene_schema()) {
    CAPTURE(s.key);
    if (is_block(s.type)) {
      CHECK(s.binding == nullptr);
    } else {
      CHECK((s.binding != nullptr) == (by_hand.count(s.key) == 0));
    }
    if (s.type == KeyType::Enum) CHECK(!s.choices.empty());  // from the enum's word table
  }
}

TEST_CASE("schema: every bound default equals the struct's default member value", "[scene]") {
  const Scene scene = parse_scene(kScene, "scenes/defaults.yaml");
  int compared = 0;
  std::set<std::string> checked;
  for (const KeySpec& row : scene_schema()) {
    if (!row.binding || row.presence != Presence::Default) continue;
    CAPTURE(row.key);
    const std::type_index t = row.binding->owner;
    auto check = [&](bool same) {
      CHECK(same);
      ++compared;
      checked.insert(row.key);
    };
    if (t == typeid(ShotSettings)) check(same_as_default(row, scene.shot));
    if (t == typeid(PrerollSettings)) check(same_as_default(row, scene.preroll));
    if (t == typeid(OutputSettings)) check(same_as_default(row, scene.output));
    if (t == typeid(RenderSettings)) check(same_as_default(row, scene.render));
    if (t == typeid(RenderCamera)) check(same_as_default(row, scene.render.cameras[0]));
    if (t == typeid(SourceDesc)) check(same_as_default(row, scene.sources[0]));
    if (t == typeid(ColliderDesc)) check(same_as_default(row, scene.colliders[0]));
    if (t == typeid(Keyframe)) check(same_as_default(row, scene.colliders[0].keyframes[0]));
    if (t == typeid(ShellMaterialDesc)) check(same_as_default(row, scene.shell_materials[0]));
    if (t == typeid(PinDesc)) check(same_as_default(row, scene.shells[0].pins[0]));
    if (t == typeid(MaterialDesc)) {
      for (const MaterialDesc& m : scene.materials) {
        const std::string type = word_of(m.kind);
        if (row.only_for.empty() || row.only_for[0] == type) check(same_as_default(row, m));
      }
    }
    if (t == typeid(ShellDesc)) {
      for (const ShellDesc& sh : scene.shells) {
        const std::string type = word_of(sh.kind);
        const bool allowed =
            row.only_for.empty() ||
            std::find(row.only_for.begin(), row.only_for.end(), type) != row.only_for.end();
        if (allowed) check(same_as_default(row, sh));
      }
    }
  }
  // Every Default row of the structs above was compared at least once (mesh shapes'
  // scale and translate need a mesh file and are compared by the reader tests).
  int rows = 0;
  for (const KeySpec& row : scene_schema())
    if (row.binding && row.presence == Presence::Default && row.key.rfind("shape.", 0) != 0) ++rows;
  CHECK(static_cast<int>(checked.size()) == rows);
  CHECK(compared > 90);
}

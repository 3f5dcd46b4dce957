// Tests of io/scene_reader: valid scenes, defaults, JSON, --set overrides, the error
// messages for bad input (file, line, key path), and that docs/scene-format.md documents
// exactly the keys, types, units, defaults and ranges the reader validates.
#include <catch2/catch.hpp>

#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "io/scene_reader.h"
#include "sim/scene/scene_words.h"

#ifndef SHELLMPM_SOURCE_DIR
#error "SHELLMPM_SOURCE_DIR must be defined to the repository root"
#endif

using namespace shellmpm;

namespace {

const std::string kSource = SHELLMPM_SOURCE_DIR;
const std::string kScenes = kSource + "/tests/data/scenes/";

// A valid scene head; lines 1-4. Cases below append lines from line 5 on.
const std::string kHead =
    "version: 1\n"
    "shot:\n"
    "  domain: {min: [-1, -1, -1], max: [1, 1, 1]}\n"
    "  dx: 0.1\n";

const std::string kSand =  // lines 5-6 after kHead
    "materials:\n"
    "  - {name: sand, type: sand}\n";

/// Runs `fn`, which must throw UserError; returns it.
template <class Fn>
UserError catch_user_error(Fn&& fn) {
  try {
    fn();
  } catch (const UserError& e) {
    return e;
  }
  FAIL("expected a UserError");
  throw std::logic_error("unreachable");
}

/// Parses `text` as "scenes/bad.yaml" and checks the error's line, key and message parts.
void expect_error(const std::string& text, int line, const std::string& key,
                  const std::vector<std::string>& parts,
                  const std::vector<std::string>& overrides = {}) {
  CAPTURE(text);
  const UserError e = catch_user_error([&] { parse_scene(text, "scenes/bad.yaml", overrides); });
  const std::string what = e.what();
  CAPTURE(what);
  CHECK(e.file == "scenes/bad.yaml");
  CHECK(e.line == line);
  CHECK(e.key == key);
  const std::string prefix = "scenes/bad.yaml" + (line > 0 ? ":" + std::to_string(line) : "") +
                             ": " + (key.empty() ? "" : key + ": ");
  CHECK(what.compare(0, prefix.size(), prefix) == 0);
  for (const std::string& p : parts) CHECK(what.find(p) != std::string::npos);
}

/// Same for an error that comes from an override: reported at "--set KEY=VALUE", no line.
void expect_override_error(const std::string& text, const std::string& ov, const std::string& key,
                           const std::vector<std::string>& parts) {
  const UserError e = catch_user_error([&] { parse_scene(text, "scenes/ok.yaml", {ov}); });
  const std::string what = e.what();
  CAPTURE(ov, what);
  CHECK(e.file == "--set " + ov);
  CHECK(e.line == 0);
  CHECK(e.key == key);
  const std::string prefix = "--set " + ov + ": " + (key.empty() ? "" : key + ": ");
  CHECK(what.compare(0, prefix.size(), prefix) == 0);
  for (const std::string& p : parts) CHECK(what.find(p) != std::string::npos);
}

bool vec_eq(const Vec3d& a, const Vec3d& b) {
  return (a - b).cwiseAbs().maxCoeff() <= 1e-12;
}

std::string trim(const std::string& s) {
  const std::size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const std::size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split_row(const std::string& line) {
  std::vector<std::string> cells;
  std::string t = trim(line);
  if (t.size() < 2 || t.front() != '|' || t.back() != '|') return cells;
  t = t.substr(1, t.size() - 2);
  std::stringstream ss(t);
  std::string cell;
  while (std::getline(ss, cell, '|')) cells.push_back(trim(cell));
  return cells;
}

}  // namespace

TEST_CASE("a full scene parses with the values written", "[scene]") {
  const Scene s = read_scene(kScenes + "full.yaml");
  CHECK(s.path == kScenes + "full.yaml");

  const ShotSettings& shot = s.shot;
  CHECK(shot.frame_start == 2);
  CHECK(shot.frame_end == 60);
  CHECK(shot.fps == 30.0);
  CHECK(shot.cfl == 0.5);
  CHECK(shot.dt_min == 1e-7);
  CHECK(shot.dt_max == 5e-3);
  CHECK(vec_eq(shot.gravity, Vec3d(0, -3.5, 0.25)));
  CHECK(vec_eq(shot.domain_min, Vec3d(-2, 0, -2)));
  CHECK(vec_eq(shot.domain_max, Vec3d(2, 3, 2)));
  CHECK(shot.dx == 0.05);
  CHECK(shot.threads == 4);
  CHECK(shot.transfer == Transfer::Mls);
  CHECK(shot.units == "cm");

  REQUIRE(s.materials.size() == 3);
  const MaterialDesc& sand = s.materials[0];
  CHECK(sand.name == "sand");
  CHECK(sand.kind == MaterialKind::Sand);
  CHECK(sand.youngs_modulus == 3.5e5);
  CHECK(sand.poisson_ratio == 0.29);
  CHECK(sand.density == 1600.0);
  CHECK(sand.friction_angle_deg == 35.0);
  CHECK(sand.cohesion == 0.01);
  const MaterialDesc& snow = s.materials[1];
  CHECK(snow.kind == MaterialKind::Snow);
  CHECK(snow.critical_compression == 0.02);
  CHECK(snow.critical_stretch == 0.006);
  CHECK(snow.hardening == 9.0);
  CHECK(snow.density == 400.0);
  const MaterialDesc& jelly = s.materials[2];
  CHECK(jelly.kind == MaterialKind::Elastic);
  CHECK(jelly.model == ElasticModel::NeoHookean);
  CHECK(jelly.youngs_modulus == 2e4);

  REQUIRE(s.sources.size() == 4);
  const SourceDesc& pile = s.sources[0];
  CHECK(pile.name == "pile");
  CHECK(pile.material == 0);
  CHECK(pile.shape.kind == ShapeDesc::Kind::Box);
  CHECK(vec_eq(pile.shape.min, Vec3d(-0.5, 0, -0.5)));
  CHECK(vec_eq(pile.shape.max, Vec3d(0.5, 1, 0.5)));
  CHECK(pile.particles_per_cell == 16.0);
  CHECK(pile.seed == 7u);
  CHECK_FALSE(pile.emit);
  const SourceDesc& flake = s.sources[1];
  CHECK(flake.name == "source1");
  CHECK(flake.material == 1);
  CHECK(flake.shape.kind == ShapeDesc::Kind::Sphere);
  CHECK(vec_eq(flake.shape.center, Vec3d(0, 2, 0)));
  CHECK(flake.shape.radius == 0.25);
  CHECK(vec_eq(flake.velocity, Vec3d(0, -1, 0)));
  CHECK(flake.emit);
  CHECK(flake.emit_start == 3);
  CHECK(flake.emit_end == 30);
  const SourceDesc& blob = s.sources[2];
  CHECK(blob.shape.kind == ShapeDesc::Kind::Cylinder);
  CHECK(vec_eq(blob.shape.axis, Vec3d(0, 1, 0)));  // normalized from [0, 2, 0]
  CHECK(blob.shape.radius == 0.2);
  CHECK(blob.shape.height == 0.5);
  CHECK(vec_eq(blob.shape.center, Vec3d(1, 1, 1)));
  const SourceDesc& rock = s.sources[3];
  CHECK(rock.material == 2);
  CHECK(rock.shape.kind == ShapeDesc::Kind::Mesh);
  CHECK(rock.shape.mesh_path == kScenes + "tetra.obj");  // resolved next to the scene file
  CHECK(rock.shape.mesh_scale == 0.5);
  CHECK(vec_eq(rock.shape.mesh_translate, Vec3d(0, 1, 0)));
  CHECK(rock.shape.sdf == nullptr);  // meshes are not loaded by the reader
  CHECK(rock.shape.mesh_where == kScenes + "full.yaml:58: sources[3].shape.path");

  REQUIRE(s.colliders.size() == 3);
  const ColliderDesc& ground = s.colliders[0];
  CHECK(ground.name == "ground");
  CHECK(ground.shape.kind == ShapeDesc::Kind::Plane);
  CHECK(vec_eq(ground.shape.normal, Vec3d(0, 1, 0)));  // normalized from [0, 3, 0]
  CHECK(ground.boundary == BoundaryKind::Sticky);
  CHECK(ground.keyframes.empty());
  const ColliderDesc& paddle = s.colliders[1];
  CHECK(paddle.boundary == BoundaryKind::Slip);
  CHECK(paddle.friction == 0.4);
  REQUIRE(paddle.keyframes.size() == 3);
  CHECK(paddle.keyframes[0].time == 0.0);
  CHECK(paddle.keyframes[1].time == Approx(23.0 / 30.0));  // frame N -> (N - 1) / fps
  CHECK(vec_eq(paddle.keyframes[1].translate, Vec3d(1, 0, 0)));
  CHECK(vec_eq(paddle.keyframes[1].rotate_deg, Vec3d(0, 90, 0)));
  CHECK(paddle.keyframes[2].time == 2.5);
  CHECK(vec_eq(paddle.keyframes[2].translate, Vec3d(0, 0, 0)));
  CHECK(vec_eq(paddle.keyframes[2].rotate_deg, Vec3d(0, 180, 0)));
  CHECK(s.colliders[2].name == "collider2");
  CHECK(s.colliders[2].boundary == BoundaryKind::Separate);

  const OutputSettings& o = s.output;
  CHECK(o.directory == "/tmp/shellmpm_full");
  CHECK_FALSE(o.density);
  CHECK(o.density_pattern == "dens_####.vdb");
  CHECK(o.velocity);
  CHECK(o.half_float);
  CHECK(o.voxel_size == 0.025);
  CHECK(o.particles);
  CHECK(o.particles_pattern == "p.######.bin");
  CHECK(o.stats_file == "run.json");
  CHECK(o.checkpoint_every == 10);
}

TEST_CASE("keys left out take the defaults of scene.h", "[scene]") {
  const Scene s = read_scene(kScenes + "minimal.yaml");
  const ShotSettings d;
  CHECK(s.shot.frame_start == d.frame_start);
  CHECK(s.shot.frame_end == d.frame_end);
  CHECK(s.shot.fps == d.fps);
  CHECK(s.shot.cfl == d.cfl);
  CHECK(s.shot.dt_min == d.dt_min);
  CHECK(s.shot.dt_max == d.dt_max);
  CHECK(vec_eq(s.shot.gravity, d.gravity));
  CHECK(s.shot.threads == d.threads);
  CHECK(s.shot.transfer == d.transfer);
  CHECK(s.shot.units == d.units);
  CHECK(s.shot.dx == 0.1);
  CHECK(s.materials.empty());
  CHECK(s.sources.empty());
  CHECK(s.colliders.empty());

  const OutputSettings od;
  CHECK(s.output.directory == od.directory);
  CHECK(s.output.density == od.density);
  CHECK(s.output.density_pattern == od.density_pattern);
  CHECK(s.output.velocity == od.velocity);
  CHECK(s.output.half_float == od.half_float);
  CHECK(s.output.voxel_size == od.voxel_size);
  CHECK(s.output.particles == od.particles);
  CHECK(s.output.particles_pattern == od.particles_pattern);
  CHECK(s.output.stats_file == od.stats_file);
  CHECK(s.output.checkpoint_every == od.checkpoint_every);

  // Materials, sources, colliders, keyframes and mesh shapes with only required keys.
  const Scene m = parse_scene(kHead +
                                  "materials:\n"
                                  "  - {name: e, type: elastic}\n"
                                  "  - {name: s, type: sand}\n"
                                  "  - {name: w, type: snow}\n"
                                  "sources:\n"
                                  "  - {material: s, shape: {type: sphere, center: [0, 0, 0],"
                                  " radius: 0.1}}\n"
                                  "colliders:\n"
                                  "  - shape: {type: mesh, path: tetra.obj}\n"
                                  "    keyframes: [{time: 0}]\n",
                              kScenes + "inline.yaml");
  const MaterialDesc md;
  REQUIRE(m.materials.size() == 3);
  for (const MaterialDesc& mat : m.materials) {
    CHECK(mat.youngs_modulus == md.youngs_modulus);
    CHECK(mat.poisson_ratio == md.poisson_ratio);
    CHECK(mat.density == md.density);
  }
  CHECK(m.materials[0].model == md.model);
  CHECK(m.materials[1].friction_angle_deg == md.friction_angle_deg);
  CHECK(m.materials[1].cohesion == md.cohesion);
  CHECK(m.materials[2].critical_compression == md.critical_compression);
  CHECK(m.materials[2].critical_stretch == md.critical_stretch);
  CHECK(m.materials[2].hardening == md.hardening);

  const SourceDesc sd;
  REQUIRE(m.sources.size() == 1);
  CHECK(m.sources[0].name == "source0");
  CHECK(m.sources[0].material == 1);
  CHECK(m.sources[0].particles_per_cell == sd.particles_per_cell);
  CHECK(vec_eq(m.sources[0].velocity, sd.velocity));
  CHECK(m.sources[0].seed == sd.seed);
  CHECK(m.sources[0].emit == sd.emit);

  const ColliderDesc cd;
  const ShapeDesc shd;
  const Keyframe kd;
  REQUIRE(m.colliders.size() == 1);
  CHECK(m.colliders[0].name == "collider0");
  CHECK(m.colliders[0].boundary == cd.boundary);
  CHECK(m.colliders[0].friction == cd.friction);
  CHECK(m.colliders[0].shape.mesh_scale == shd.mesh_scale);
  CHECK(vec_eq(m.colliders[0].shape.mesh_translate, shd.mesh_translate));
  REQUIRE(m.colliders[0].keyframes.size() == 1);
  CHECK(vec_eq(m.colliders[0].keyframes[0].translate, kd.translate));
  CHECK(vec_eq(m.colliders[0].keyframes[0].rotate_deg, kd.rotate_deg));
}

TEST_CASE("JSON scenes are read like YAML", "[scene]") {
  const Scene s = read_scene(kScenes + "minimal.json");
  CHECK(s.shot.dx == 0.1);
  CHECK(s.shot.frame_end == 10);
  REQUIRE(s.materials.size() == 1);
  CHECK(s.materials[0].density == 900.0);
  REQUIRE(s.sources.size() == 1);
  CHECK(s.sources[0].shape.kind == ShapeDesc::Kind::Sphere);
  CHECK(s.output.directory == "json_out");

  // JSON errors carry lines too; a quoted number is a string, not a number.
  expect_error(
      "{\n"
      "  \"version\": 1,\n"
      "  \"shot\": {\"domain\": {\"min\": [0, 0, 0], \"max\": [1, 1, 1]},\n"
      "           \"dx\": \"0.1\"}\n"
      "}\n",
      4, "shot.dx", {"expected a number", "\"0.1\"", "without quotes"});
}

TEST_CASE("overrides (--set) change the document before validation", "[scene]") {
  const std::string text = kHead + kSand +
                           "sources:\n"
                           "  - {material: sand, shape: {type: box, min: [0, 0, 0],"
                           " max: [1, 1, 1]}}\n";
  SECTION("scalars, vectors and list entries, both index spellings") {
    const Scene s =
        parse_scene(text, "scenes/ok.yaml",
                    {"shot.dx=0.01", "shot.gravity=[0,-1,0]", "materials.0.density=1500",
                     "materials[0].friction_angle=40", "sources[0].shape.max=[2, 2, 2]",
                     "output.directory=/tmp/x", "shot.frames=[1, 10]"});
    CHECK(s.shot.dx == 0.01);
    CHECK(vec_eq(s.shot.gravity, Vec3d(0, -1, 0)));
    CHECK(s.materials[0].density == 1500.0);
    CHECK(s.materials[0].friction_angle_deg == 40.0);
    CHECK(vec_eq(s.sources[0].shape.max, Vec3d(2, 2, 2)));
    CHECK(s.output.directory == "/tmp/x");  // created: the file has no output block
    CHECK(s.shot.frame_end == 10);
  }
  SECTION("a mesh path from an override is resolved next to the scene file") {
    const std::string ov = "sources.0.shape={type: mesh, path: tetra.obj}";
    const Scene s = parse_scene(text, kScenes + "ok.yaml", {ov});
    CHECK(s.sources[0].shape.mesh_path == kScenes + "tetra.obj");
    CHECK(s.sources[0].shape.mesh_where == "--set " + ov + ": sources[0].shape.path");
  }
  SECTION("later overrides win; a mapping value replaces the whole mapping") {
    const Scene s = parse_scene(text, "scenes/ok.yaml",
                                {"shot.dx=0.05", "shot.dx=0.025",
                                 "sources.0.shape={type: sphere, center: [0,0,0], radius: 1}"});
    CHECK(s.shot.dx == 0.025);
    CHECK(s.sources[0].shape.kind == ShapeDesc::Kind::Sphere);
  }
  SECTION("unknown keys") {
    expect_override_error(text, "shot.dxx=1", "shot.dxx",
                          {"unknown key 'dxx' in shot (known: frames, fps,", "dx"});
    expect_override_error(text, "shots.dx=1", "shots",
                          {"unknown key 'shots' in the top level", "shot"});
    expect_override_error(text, "materials[0].densty=1", "materials[0].densty",
                          {"unknown key 'densty' in materials[0]", "density"});
    expect_override_error(text, "shot.dx.value=1", "shot.dx.value",
                          {"unknown key 'value' in shot.dx", "no sub-keys"});
  }
  SECTION("bad values are reported at the override") {
    expect_override_error(text, "shot.dx=abc", "shot.dx", {"expected a number, got 'abc'"});
    expect_override_error(text, "shot.dx=-1", "shot.dx", {"must be in [1e-6, 1000], got -1"});
    expect_override_error(text, "shot.gravity=[0,1]", "shot.gravity",
                          {"expected a list of 3 numbers"});
    expect_override_error(text, "materials.0.type=clay", "materials[0].type",
                          {"expected one of elastic, sand, snow, got 'clay'"});
    expect_override_error(text, "shot.dx=[0.1", "shot.dx", {"YAML syntax error"});
    expect_override_error(text, "shot.dx=", "shot.dx", {"expected a number, got nothing"});
  }
  SECTION("bad key paths") {
    expect_override_error(text, "materials[3].density=1", "materials[3]",
                          {"index 3 is out of range: materials has 1 entry"});
    expect_override_error(text, "colliders[0].friction=1", "colliders[0]",
                          {"out of range: colliders has 0 entries"});
    expect_override_error(text, "materials.density=1", "materials.density",
                          {"materials is a list", "materials[0].density"});
    expect_override_error(text, "shot[0]=1", "shot[0]", {"shot is not a list"});
    expect_override_error(text, "shot.dx", "", {"expected KEY=VALUE"});
    expect_override_error(text, "shot..dx=1", "", {"bad key path", "empty key name"});
    expect_override_error(text, "materials[x].density=1", "", {"list index must be a number"});
  }
}

TEST_CASE("bad scenes name the file, line and key", "[scene]") {
  SECTION("wrong type") {
    expect_error(kHead + "  fps: fast\n", 5, "shot.fps", {"expected a number, got 'fast'"});
    expect_error(kHead + "  fps: \"24\"\n", 5, "shot.fps", {"without quotes"});
    expect_error(kHead + "  threads: 2.5\n", 5, "shot.threads", {"expected an integer, got '2.5'"});
    expect_error(kHead + "  fps:\n", 5, "shot.fps", {"expected a number, got nothing (null)"});
    expect_error(kHead + "output: {density: yes}\n", 5, "output.density",
                 {"expected true or false, got 'yes'"});
    expect_error(kHead + "materials:\n", 5, "materials", {"expected a list", "[]"});
    expect_error(kHead + "output: out\n", 5, "output", {"expected a mapping", "'out'"});
    expect_error(kHead + "  fps: .inf\n", 5, "shot.fps", {"must be a finite number"});
    expect_error(kHead + "  fps: 1e999\n", 5, "shot.fps", {"out of the range of a double"});
  }
  SECTION("missing required key") {
    expect_error("version: 1\nshot:\n  dx: 0.1\n", 3, "shot.domain",
                 {"required key 'domain' is missing"});
    expect_error("version: 1\n", 1, "shot", {"required key 'shot' is missing"});
    expect_error(kHead + "materials:\n  - {name: m}\n", 6, "materials[0].type",
                 {"required key 'type' is missing", "elastic, sand, snow"});
    expect_error(kHead + "colliders:\n  - shape: {type: sphere, center: [0, 0, 0]}\n", 6,
                 "colliders[0].shape.radius", {"required key 'radius' is missing"});
  }
  SECTION("unknown keys, top-level and nested") {
    expect_error(kHead + "colider: []\n", 5, "colider",
                 {"unknown key 'colider' in the top level",
                  "(known: version, shot, materials, sources, colliders, shell_materials, shells, "
                  "preroll, output, render)"});
    expect_error(kHead + "  dxx: 0.2\n", 5, "shot.dxx",
                 {"unknown key 'dxx' in shot (known: frames, fps, cfl,"});
    expect_error(kHead + kSand + "sources:\n  - material: sand\n    colour: red\n", 9,
                 "sources[0].colour", {"unknown key 'colour' in sources[0]"});
    expect_error(kHead +
                     "colliders:\n  - shape: {type: box, min: [0,0,0], max: [1,1,1],\n"
                     "      size: 2}\n",
                 7, "colliders[0].shape.size",
                 {"unknown key 'size'", "known for type box: type, min, max"});
  }
  SECTION("out-of-range values") {
    expect_error(kHead + "  cfl: 1.5\n", 5, "shot.cfl", {"must be in (0, 1], got 1.5"});
    expect_error(kHead + "  frames: [0, 10]\n", 5, "shot.frames[0]",
                 {"must be in [1, 999999999], got 0"});
    expect_error(kHead + "  frames: [1, 1000000000]\n", 5, "shot.frames[1]",
                 {"must be in [1, 999999999], got 1000000000"});
    expect_error(kHead + "  frames: [10, 5]\n", 5, "shot.frames",
                 {"last frame 5 is before first frame 10"});
    expect_error(kHead + "materials:\n  - {name: m, type: elastic, poisson_ratio: 0.5}\n", 6,
                 "materials[0].poisson_ratio", {"must be in [0, 0.5), got 0.5"});
    expect_error(kHead + "  dt_min: 0.1\n", 5, "shot.dt_min",
                 {"dt_max (0.01) must be >= dt_min (0.1)"});
    // A domain too many cells across is also too far from the origin for float (2^17 dx
    // from it, 2^18 cells across at most): that is the error it gets.
    expect_error("version: 1\nshot:\n  domain: {min: [0, 0, 0], max: [10, 1, 1]}\n  dx: 1e-5\n", 3,
                 "shot.domain.max[0]", {"coordinate x = 10 m", "2^17 = 131072 cells"});
    expect_error("version: 1\nshot:\n  domain: {min: [0, 0, 0], max: [1, 0, 1]}\n  dx: 0.1\n", 3,
                 "shot.domain.max", {"on y max = 0 <= min = 0"});
    const UserError e = catch_user_error([] { read_scene(kScenes + "bad_range.yaml"); });
    CHECK(std::string(e.what()) ==
          kScenes + "bad_range.yaml:8: materials[0].density: must be in [0.1, 100000], got -3");
  }
  SECTION("bad enum") {
    expect_error(kHead + "  transfer: flip\n", 5, "shot.transfer",
                 {"expected one of apic, mls, got 'flip'"});
    expect_error(kHead + "colliders:\n  - shape: {type: cone}\n", 6, "colliders[0].shape.type",
                 {"expected one of plane, box, sphere, cylinder, mesh, got 'cone'"});
  }
  SECTION("missing mesh file") {
    const UserError e = catch_user_error([] { read_scene(kScenes + "bad_missing_mesh.yaml"); });
    CHECK(e.file == kScenes + "bad_missing_mesh.yaml");
    CHECK(e.line == 11);
    CHECK(e.key == "colliders[0].shape.path");
    CHECK(std::string(e.what()).find("mesh file not found: " + kScenes + "no_such_mesh.obj") !=
          std::string::npos);
    expect_error(kHead + "colliders:\n  - shape: {type: mesh, path: /}\n", 6,
                 "colliders[0].shape.path", {"not a regular file"});
  }
  SECTION("duplicate names and keys") {
    expect_error(kHead + "materials:\n  - {name: sand, type: sand}\n  - {name: sand, type: snow}\n",
                 7, "materials[1].name", {"duplicate material name 'sand' (also materials[0])"});
    expect_error(kHead + "  dx: 0.2\n", 5, "shot.dx", {"duplicate key 'dx' (first at line 4)"});
    expect_error(kHead + kSand +
                     "sources:\n"
                     "  - {name: a, material: sand, shape: {type: sphere, center: [0,0,0], "
                     "radius: 1}}\n"
                     "  - {name: a, material: sand, shape: {type: sphere, center: [0,0,0], "
                     "radius: 1}}\n",
                 9, "sources[1].name", {"duplicate source name 'a'"});
  }
  SECTION("unknown material reference") {
    expect_error(kHead + kSand +
                     "sources:\n  - {material: sandd, shape: {type: box, min: [0,0,0], "
                     "max: [1,1,1]}}\n",
                 8, "sources[0].material", {"unknown material 'sandd' (materials: sand)"});
    expect_error(kHead +
                     "sources:\n  - {material: sand, shape: {type: box, min: [0,0,0], "
                     "max: [1,1,1]}}\n",
                 6, "sources[0].material", {"no materials are defined"});
  }
  SECTION("YAML syntax errors") {
    const UserError e = catch_user_error([] { read_scene(kScenes + "bad_syntax.yaml"); });
    CHECK(e.file == kScenes + "bad_syntax.yaml");
    CHECK(e.line >= 4);  // the unclosed '[' is on line 4; yaml-cpp notices it on line 5
    CHECK(e.line <= 5);
    CHECK(std::string(e.what()).find("YAML syntax error") != std::string::npos);
    expect_error(kHead + "  fps: 24\n bad indent: 1\n", 6, "", {"YAML syntax error"});
    expect_error(kHead + "---\nversion: 1\n", 0, "", {"2 YAML documents"});
  }
  SECTION("wrong vector length") {
    expect_error(kHead + "  gravity: [0, -9.81]\n", 5, "shot.gravity",
                 {"expected a list of 3 numbers [x, y, z], got a list of 2 items"});
    expect_error(kHead + "  gravity: [0, g, 0]\n", 5, "shot.gravity[1]",
                 {"expected a number, got 'g'"});
    expect_error(kHead + "  frames: [1, 2, 3]\n", 5, "shot.frames",
                 {"expected [first, last] frames"});
  }
  SECTION("keyframes must strictly increase in time") {
    const std::string c =
        "colliders:\n"
        "  - shape: {type: sphere, center: [0, 0, 0], radius: 0.1}\n"
        "    keyframes:\n"
        "      - {time: 0}\n"
        "      - {time: 1}\n"
        "      - {time: 1, translate: [1, 0, 0]}\n";
    expect_error(kHead + c, 10, "colliders[0].keyframes[2].time",
                 {"strictly increase: 1 s is not after 1 s"});
    // frame 24 at 24 fps is t = 1 s, the same as the key before it
    const std::string f =
        "colliders:\n"
        "  - shape: {type: sphere, center: [0, 0, 0], radius: 0.1}\n"
        "    keyframes:\n"
        "      - {time: 1.0}\n"
        "      - {frame: 24}\n";
    expect_error(kHead + f, 9, "colliders[0].keyframes[1].frame", {"strictly increase"});
    expect_error(kHead +
                     "colliders:\n"
                     "  - shape: {type: sphere, center: [0, 0, 0], radius: 0.1}\n"
                     "    keyframes:\n"
                     "      - {time: 1.0, frame: 24}\n",
                 8, "colliders[0].keyframes[0]", {"either time or frame, not both"});
    expect_error(kHead +
                     "colliders:\n"
                     "  - shape: {type: sphere, center: [0, 0, 0], radius: 0.1}\n"
                     "    keyframes:\n"
                     "      - {translate: [0, 0, 0]}\n",
                 8, "colliders[0].keyframes[0]", {"needs a time (seconds) or a frame"});
  }
  SECTION("emission needs a nonzero velocity") {
    expect_error(kHead + kSand +
                     "sources:\n"
                     "  - material: sand\n"
                     "    shape: {type: sphere, center: [0, 0, 0], radius: 0.1}\n"
                     "    emit: {frames: [1, 10]}\n",
                 10, "sources[0].emit", {"nonzero velocity", "sources[0].velocity"});
  }
  SECTION("version missing or wrong, checked first") {
    expect_error("shot: {domain: {min: [0,0,0], max: [1,1,1]}, dx: 0.1}\n", 1, "version",
                 {"required key 'version' is missing"});
    expect_error("version: 2\nnew_key_of_v2: 1\n", 1, "version", {"must be 1, got 2"});
  }
  SECTION("keys of one material type on another") {
    expect_error(kHead + "materials:\n  - {name: j, type: elastic, friction_angle: 30}\n", 6,
                 "materials[0].friction_angle",
                 {"'friction_angle' is not allowed for type elastic (only for sand"});
    expect_error(kHead + "materials:\n  - {name: s, type: sand, model: neo_hookean}\n", 6,
                 "materials[0].model", {"not allowed for type sand (only for elastic"});
    expect_error(kHead + "materials:\n  - {name: s, type: sand, hardening: 3}\n", 6,
                 "materials[0].hardening", {"only for snow"});
  }
  SECTION("shapes") {
    expect_error(kHead + kSand +
                     "sources:\n  - {material: sand, shape: {type: plane, point: [0,0,0], "
                     "normal: [0,1,0]}}\n",
                 8, "sources[0].shape.type", {"a plane cannot be a source"});
    expect_error(kHead +
                     "colliders:\n  - shape: {type: sphere, center: [0,0,0], radius: 1, "
                     "min: [0,0,0]}\n",
                 6, "colliders[0].shape.min",
                 {"'min' is not allowed for type sphere", "keys for sphere: type, center, radius"});
    expect_error(kHead + "colliders:\n  - shape: {type: plane, point: [0,0,0], normal: [0,0,0]}\n",
                 6, "colliders[0].shape.normal", {"nonzero"});
    expect_error(kHead + "colliders:\n  - shape: {type: box, min: [0,0,0], max: [1,1,-1]}\n", 6,
                 "colliders[0].shape.max", {"on z max = -1 <= min = 0"});
  }
  SECTION("output patterns") {
    expect_error(kHead + "output:\n  density_pattern: density.vdb\n", 6, "output.density_pattern",
                 {"exactly one run of '#'", "'density.vdb'"});
    expect_error(kHead + "output:\n  particles_pattern: p.##.#.bin\n", 6,
                 "output.particles_pattern", {"exactly one run of '#'"});
  }
  SECTION("the document itself") {
    expect_error("", 0, "", {"the scene is empty"});
    expect_error("- version: 1\n", 1, "", {"expected a mapping of keys at the top level"});
    const UserError e = catch_user_error([] { read_scene(kScenes + "no_such_scene.yaml"); });
    CHECK(e.file == kScenes + "no_such_scene.yaml");
    CHECK(e.line == 0);
    CHECK(std::string(e.what()).find("cannot open scene file") != std::string::npos);
  }
}

TEST_CASE("a shell scene parses with the values written", "[scene][shell]") {
  const std::string file = kScenes + "shells.yaml";
  const Scene s = read_scene(file);
  CHECK(s.materials.empty());  // shells need no bulk materials or sources
  CHECK(s.sources.empty());

  REQUIRE(s.shell_materials.size() == 2);
  const ShellMaterialDesc& cotton = s.shell_materials[0];
  CHECK(cotton.name == "cotton");
  CHECK(cotton.youngs_modulus == 2.5e6);
  CHECK(cotton.poisson_ratio == 0.35);
  CHECK(cotton.density == 500.0);
  CHECK(cotton.thickness == 0.002);
  CHECK(cotton.yield_stress == 1e4);
  CHECK(cotton.damping == 0.5);
  CHECK(cotton.stiffness_damping == 1e-4);
  CHECK(cotton.quadrature_inplane == 6);
  CHECK(cotton.quadrature_thickness == 5);
  CHECK(s.shell_materials[1].name == "tin");
  CHECK(s.shell_materials[1].stretch_limit == 1.7);

  REQUIRE(s.shells.size() == 4);
  const ShellDesc& cloth = s.shells[0];
  CHECK(cloth.name == "cloth-1");
  CHECK(cloth.material == 0);
  CHECK(cloth.kind == ShellDesc::Kind::Sheet);
  CHECK(cloth.size[0] == 2.0);
  CHECK(cloth.size[1] == 1.5);
  CHECK(cloth.resolution[0] == 20);
  CHECK(cloth.resolution[1] == 10);
  CHECK(cloth.scale == 0.5);
  CHECK(vec_eq(cloth.rotate_deg, Vec3d(90, 0, 45)));
  CHECK(vec_eq(cloth.translate, Vec3d(0, 1, 0)));
  CHECK(vec_eq(cloth.velocity, Vec3d(0, -1, 0)));
  CHECK(cloth.pressure == 12.5);
  REQUIRE(cloth.point_loads.size() == 1);
  CHECK(cloth.point_loads[0].index == 230);  // the last of (20 + 1) * (10 + 1) vertices
  CHECK(vec_eq(cloth.point_loads[0].force, Vec3d(0, -2, 0)));
  CHECK(cloth.point_loads[0].where == file + ":30: shells[0].point_loads[0].index");
  REQUIRE(cloth.pins.size() == 2);
  const PinDesc& p0 = cloth.pins[0];
  CHECK(p0.indices == std::vector<int>{0, 20});
  CHECK_FALSE(p0.has_box);
  CHECK(p0.group.empty());
  CHECK(p0.components[0]);
  CHECK_FALSE(p0.components[1]);
  CHECK(p0.components[2]);
  CHECK(p0.where == file + ":32: shells[0].pins[0].indices");
  REQUIRE(p0.keyframes.size() == 2);
  CHECK(p0.keyframes[0].time == 0.0);
  CHECK(p0.keyframes[1].time == Approx(1.0));  // frame 26 at 25 fps
  CHECK(vec_eq(p0.keyframes[1].translate, Vec3d(0, 1, 0)));
  CHECK(vec_eq(p0.keyframes[1].rotate_deg, Vec3d(0, 45, 0)));
  const PinDesc& p1 = cloth.pins[1];
  CHECK(p1.has_box);
  CHECK(p1.indices.empty());
  CHECK(vec_eq(p1.box_min, Vec3d(-1, -1, -1)));
  CHECK(vec_eq(p1.box_max, Vec3d(1, 1, -0.5)));
  CHECK(p1.keyframes.empty());
  CHECK(cloth.output_refine == 2);
  CHECK_FALSE(cloth.write_mesh);

  const ShellDesc& can = s.shells[1];
  CHECK(can.name == "can");
  CHECK(can.material == 1);
  CHECK(can.kind == ShellDesc::Kind::Cylinder);
  CHECK(can.radius == 0.1);
  CHECK(can.height == 0.3);
  CHECK(can.angle_deg == 180.0);
  CHECK(can.resolution[0] == 2);  // an open patch may have fewer than 3 segments around
  CHECK(can.resolution[1] == 4);

  const ShellDesc& ball = s.shells[2];
  CHECK(ball.name == "shell2");
  CHECK(ball.kind == ShellDesc::Kind::Sphere);
  CHECK(ball.radius == 0.2);
  CHECK(ball.subdivisions == 3);

  const ShellDesc& rag = s.shells[3];
  CHECK(rag.kind == ShellDesc::Kind::Mesh);
  CHECK(rag.mesh_path == kScenes + "tetra.obj");
  CHECK(rag.mesh_where == file + ":49: shells[3].geometry.path");
  CHECK(rag.mesh == nullptr);  // loaded by io/, not by the reader
  REQUIRE(rag.pins.size() == 2);
  CHECK(rag.pins[0].group == "top");
  CHECK(rag.pins[1].indices == std::vector<int>{100000});  // checked once the mesh is loaded

  CHECK(s.preroll.enabled);
  CHECK(s.preroll.tolerance == 1e-6);
  CHECK(s.preroll.max_steps == 5000);
  CHECK(s.output.shell_pattern == "shells/{name}_####.obj");
  CHECK(s.output.shell_format == MeshFormat::Obj);

  SECTION("check_shell_indices reports mesh indices at the key that gave them") {
    check_shell_indices(rag, 100001, s.path);  // in range: no error
    const UserError e = catch_user_error([&] { check_shell_indices(rag, 4, s.path); });
    CHECK(e.file == file);
    CHECK(e.line == 52);
    CHECK(e.key == "shells[3].pins[1].indices[0]");
    CHECK(std::string(e.what()).find("index 100000 is out of range") != std::string::npos);
    CHECK(std::string(e.what()).find("has 4 vertices (0..3)") != std::string::npos);
    const UserError l = catch_user_error([&] { check_shell_indices(cloth, 200, s.path); });
    CHECK(l.file == file);
    CHECK(l.line == 30);
    CHECK(l.key == "shells[0].point_loads[0].index");
    // Without a `where` (a ShellDesc built in code) the scene file and shell name are used.
    ShellDesc bare;
    bare.name = "b";
    bare.pins.push_back(PinDesc{});
    bare.pins[0].indices = {7};
    const UserError b = catch_user_error([&] { check_shell_indices(bare, 5, "x.yaml"); });
    CHECK(b.file == "x.yaml");
    CHECK(b.line == 0);
    CHECK(b.key == "shell 'b' pins[0].indices[0]");
  }
  SECTION("from an override, the location is the --set") {
    const std::string ov = "shells[3].pins[1].indices=[9]";
    const Scene o = read_scene(file, {ov});
    const UserError e = catch_user_error([&] { check_shell_indices(o.shells[3], 4, o.path); });
    CHECK(e.file == "--set " + ov);
    CHECK(e.line == 0);
    CHECK(e.key == "shells[3].pins[1].indices[0]");
  }
}

TEST_CASE("shell keys left out take the defaults of scene.h", "[scene][shell]") {
  const Scene s = parse_scene(kHead +
                                  "shell_materials: [{name: m}]\n"
                                  "shells:\n"
                                  "  - {material: m, geometry: {type: sheet}}\n"
                                  "  - material: m\n"
                                  "    geometry: {type: cylinder}\n"
                                  "    pins: [{box: {min: [0, 0, 0], max: [0, 0, 0]}}]\n"
                                  "  - {material: m, geometry: {type: sphere}}\n",
                              "scenes/defaults.yaml");
  const ShellMaterialDesc md;
  REQUIRE(s.shell_materials.size() == 1);
  const ShellMaterialDesc& m = s.shell_materials[0];
  CHECK(m.youngs_modulus == md.youngs_modulus);
  CHECK(m.poisson_ratio == md.poisson_ratio);
  CHECK(m.density == md.density);
  CHECK(m.thickness == md.thickness);
  CHECK(m.yield_stress == md.yield_stress);
  CHECK(m.stretch_limit == md.stretch_limit);
  CHECK(m.damping == md.damping);
  CHECK(m.stiffness_damping == md.stiffness_damping);
  CHECK(m.quadrature_inplane == md.quadrature_inplane);
  CHECK(m.quadrature_thickness == md.quadrature_thickness);

  const ShellDesc d;
  REQUIRE(s.shells.size() == 3);
  for (std::size_t i = 0; i < s.shells.size(); ++i) {
    const ShellDesc& sh = s.shells[i];
    CAPTURE(i);
    CHECK(sh.name == "shell" + std::to_string(i));
    CHECK(sh.material == 0);
    CHECK(sh.scale == d.scale);
    CHECK(vec_eq(sh.rotate_deg, d.rotate_deg));
    CHECK(vec_eq(sh.translate, d.translate));
    CHECK(vec_eq(sh.velocity, d.velocity));
    CHECK(sh.pressure == d.pressure);
    CHECK(sh.point_loads.empty());
    CHECK(sh.output_refine == d.output_refine);
    CHECK(sh.write_mesh == d.write_mesh);
  }
  CHECK(s.shells[0].kind == ShellDesc::Kind::Sheet);
  CHECK(s.shells[0].size[0] == d.size[0]);
  CHECK(s.shells[0].size[1] == d.size[1]);
  CHECK(s.shells[0].resolution[0] == d.resolution[0]);
  CHECK(s.shells[0].resolution[1] == d.resolution[1]);
  CHECK(s.shells[0].pins.empty());
  CHECK(s.shells[1].kind == ShellDesc::Kind::Cylinder);
  CHECK(s.shells[1].radius == d.radius);
  CHECK(s.shells[1].height == d.height);
  CHECK(s.shells[1].angle_deg == d.angle_deg);
  CHECK(s.shells[1].resolution[0] == d.resolution[0]);
  REQUIRE(s.shells[1].pins.size() == 1);
  const PinDesc pd;
  const PinDesc& pin = s.shells[1].pins[0];
  CHECK(pin.has_box);  // a zero-size box is allowed (max >= min)
  for (int a = 0; a < 3; ++a) CHECK(pin.components[a] == pd.components[a]);
  CHECK(pin.keyframes.empty());
  CHECK(s.shells[2].kind == ShellDesc::Kind::Sphere);
  CHECK(s.shells[2].radius == d.radius);
  CHECK(s.shells[2].subdivisions == d.subdivisions);

  const PrerollSettings pr;
  CHECK(s.preroll.enabled == pr.enabled);
  CHECK(s.preroll.tolerance == pr.tolerance);
  CHECK(s.preroll.max_steps == pr.max_steps);
  const OutputSettings od;
  CHECK(s.output.shell_pattern == od.shell_pattern);
  CHECK(s.output.shell_format == od.shell_format);

  // A scene without shells takes the defaults too.
  const Scene none = read_scene(kScenes + "minimal.yaml");
  CHECK(none.shell_materials.empty());
  CHECK(none.shells.empty());
  CHECK(none.preroll.enabled == pr.enabled);
  CHECK(none.output.shell_pattern == od.shell_pattern);
}

TEST_CASE("bad shell scenes name the file, line and key", "[scene][shell]") {
  // lines 5-6 after kHead
  const std::string mats =
      "shell_materials:\n"
      "  - {name: cotton}\n";
  const std::string sheet = "{type: sheet, resolution: [2, 2]}";  // 9 vertices
  SECTION("unknown shell material") {
    expect_error(kHead + mats + "shells:\n  - {material: cottn, geometry: " + sheet + "}\n", 8,
                 "shells[0].material",
                 {"unknown shell material 'cottn' (shell_materials: cotton)"});
    expect_error(kHead + "shells:\n  - {material: cotton, geometry: " + sheet + "}\n", 6,
                 "shells[0].material", {"no shell_materials are defined"});
    // bulk materials are another namespace
    expect_error(kHead + kSand + "shells:\n  - {material: sand, geometry: " + sheet + "}\n", 8,
                 "shells[0].material", {"unknown shell material 'sand'"});
  }
  SECTION("shell names") {
    expect_error(kHead + mats +
                     "shells:\n"
                     "  - {name: a, material: cotton, geometry: " +
                     sheet +
                     "}\n"
                     "  - {name: a, material: cotton, geometry: " +
                     sheet + "}\n",
                 9, "shells[1].name", {"duplicate shell name 'a' (also shells[0])"});
    expect_error(kHead + mats +
                     "shells:\n"
                     "  - {name: shell1, material: cotton, geometry: " +
                     sheet +
                     "}\n"
                     "  - {material: cotton, geometry: " +
                     sheet + "}\n",
                 9, "shells[1].name", {"duplicate shell name 'shell1' (also shells[0])"});
    expect_error(
        kHead + mats + "shells:\n  - {name: my cloth, material: cotton, geometry: " + sheet + "}\n",
        8, "shells[0].name", {"'my cloth'", "letters, digits, '_' and '-'"});
    expect_error(
        kHead + mats + "shells:\n  - {name: a/b, material: cotton, geometry: " + sheet + "}\n", 8,
        "shells[0].name", {"only letters"});
    expect_error(kHead + mats + "  - {name: cotton}\n", 7, "shell_materials[1].name",
                 {"duplicate shell material name 'cotton' (also shell_materials[0])"});
  }
  SECTION("pin selectors") {
    const std::string head = kHead + mats +
                             "shells:\n  - material: cotton\n    geometry: " + sheet +
                             "\n    pins:\n";  // pins from line 11
    expect_error(head + "      - indices: [0]\n        box: {min: [0,0,0], max: [1,1,1]}\n", 12,
                 "shells[0].pins[0].box",
                 {"give exactly one of indices, box, group", "indices and box"});
    expect_error(head + "      - {components: [true, true, true]}\n", 11, "shells[0].pins[0]",
                 {"needs exactly one of indices, box, group (none given)"});
    expect_error(head + "      - {group: top}\n", 11, "shells[0].pins[0].group",
                 {"vertex groups come from a mesh file", "shells[0].geometry.type is sheet"});
    expect_error(head + "      - {indices: [0], components: [false, false, false]}\n", 11,
                 "shells[0].pins[0].components", {"at least one of x, y, z must be true"});
    expect_error(head + "      - {indices: [0], components: [true, 1, true]}\n", 11,
                 "shells[0].pins[0].components[1]", {"expected true or false, got '1'"});
    expect_error(head + "      - {indices: [0], components: [true, true]}\n", 11,
                 "shells[0].pins[0].components", {"expected a list of 3 booleans"});
    expect_error(head + "      - {indices: []}\n", 11, "shells[0].pins[0].indices",
                 {"must not be empty"});
    expect_error(head + "      - indices:\n          - 1\n          - -2\n", 13,
                 "shells[0].pins[0].indices[1]", {"must be >= 0, got -2"});
    expect_error(head + "      - {box: {min: [0,0,0], max: [1,-1,1]}}\n", 11,
                 "shells[0].pins[0].box.max", {"on y max = -1 < min = 0"});
    expect_error(head + "      - {indices: [0], keyframes: [{frame: 5}, {frame: 5}]}\n", 11,
                 "shells[0].pins[0].keyframes[1].frame", {"strictly increase"});
    expect_error(head + "      - {indices: [0], keyframes: [{time: 0, frame: 1}]}\n", 11,
                 "shells[0].pins[0].keyframes[0]", {"either time or frame, not both"});
  }
  SECTION("indices out of range of procedural geometry") {
    const std::string head = kHead + mats +
                             "shells:\n  - material: cotton\n    geometry: " + sheet +
                             "\n";  // line 10 next
    expect_error(head + "    pins:\n      - indices:\n          - 8\n          - 9\n", 13,
                 "shells[0].pins[0].indices[1]",
                 {"index 9 is out of range: the sheet has 9 vertices (0..8)"});
    expect_error(head + "    point_loads: [{index: 9, force: [0, 1, 0]}]\n", 10,
                 "shells[0].point_loads[0].index", {"index 9 is out of range: the sheet"});
    // closed cylinder n_around * (n_along + 1) = 12, open (n_around + 1) * (n_along + 1) = 15
    const std::string cyl = kHead + mats + "shells:\n  - material: cotton\n";
    expect_error(cyl +
                     "    geometry: {type: cylinder, resolution: [4, 2]}\n"
                     "    pins: [{indices: [12]}]\n",
                 10, "shells[0].pins[0].indices[0]", {"the cylinder has 12 vertices"});
    CHECK_NOTHROW(parse_scene(cyl +
                                  "    geometry: {type: cylinder, angle: 90, resolution: [4, 2]}\n"
                                  "    pins: [{indices: [14]}]\n",
                              "scenes/ok.yaml"));
    // sphere 10 * 4^s + 2: 42 at s = 1
    expect_error(cyl +
                     "    geometry: {type: sphere, subdivisions: 1}\n"
                     "    point_loads: [{index: 42, force: [0, 0, 0]}]\n",
                 10, "shells[0].point_loads[0].index", {"the sphere has 42 vertices (0..41)"});
    CHECK_NOTHROW(parse_scene(cyl + "    geometry: {type: sphere, subdivisions: 1}\n"
                                    "    point_loads: [{index: 41, force: [0, 0, 0]}]\n",
                              "scenes/ok.yaml"));
  }
  SECTION("shell material ranges") {
    expect_error(kHead + "shell_materials:\n  - {name: m, quadrature_inplane: 4}\n", 6,
                 "shell_materials[0].quadrature_inplane", {"must be one of 1, 3, 6, 7", "got 4"});
    expect_error(kHead + "shell_materials:\n  - {name: m, thickness: 0}\n", 6,
                 "shell_materials[0].thickness", {"must be in [1e-7, 1], got 0"});
    expect_error(kHead + "shell_materials:\n  - {name: m, quadrature_thickness: 6}\n", 6,
                 "shell_materials[0].quadrature_thickness", {"must be in [1, 5], got 6"});
    expect_error(kHead + "shell_materials:\n  - {name: m, poisson_ratio: 0.5}\n", 6,
                 "shell_materials[0].poisson_ratio", {"must be in [0, 0.5)"});
    expect_error(kHead + "shell_materials:\n  - {name: m, stretch_limit: 1}\n", 6,
                 "shell_materials[0].stretch_limit", {"must be in (1, 1.9], got 1"});
    expect_error(kHead + "shell_materials:\n  - {name: m, stretch_limit: 2.5}\n", 6,
                 "shell_materials[0].stretch_limit", {"must be in (1, 1.9], got 2.5"});
    expect_error(kHead + "shell_materials:\n  - {name: m, density: 1, type: elastic}\n", 6,
                 "shell_materials[0].type", {"unknown key 'type' in shell_materials[0]"});
  }
  SECTION("geometry") {
    const std::string head = kHead + mats + "shells:\n  - material: cotton\n";  // line 9 next
    expect_error(head + "    geometry: {type: sheet, resolution: [0, 4]}\n", 9,
                 "shells[0].geometry.resolution[0]", {"must be in [1, 2000], got 0"});
    expect_error(head + "    geometry: {type: sheet, resolution: [4, 2001]}\n", 9,
                 "shells[0].geometry.resolution[1]", {"must be in [1, 2000], got 2001"});
    expect_error(head + "    geometry: {type: sheet, resolution: [4, 2.5]}\n", 9,
                 "shells[0].geometry.resolution[1]", {"expected an integer"});
    expect_error(head + "    geometry: {type: sheet, size: [1, 0]}\n", 9,
                 "shells[0].geometry.size[1]", {"must be > 0, got 0"});
    expect_error(head + "    geometry: {type: sheet, size: [1, 1, 1]}\n", 9,
                 "shells[0].geometry.size", {"expected a list of 2 numbers"});
    expect_error(head + "    geometry: {type: sphere, subdivisions: 9}\n", 9,
                 "shells[0].geometry.subdivisions", {"must be in [0, 7], got 9"});
    expect_error(head + "    geometry: {type: sphere, radius: 1, height: 2}\n", 9,
                 "shells[0].geometry.height",
                 {"'height' is not allowed for type sphere",
                  "keys for sphere: type, radius, "
                  "subdivisions"});
    expect_error(head + "    geometry: {type: cylinder, resolution: [2, 4]}\n", 9,
                 "shells[0].geometry.resolution[0]",
                 {"closed cylinder (angle 360) needs at least 3 segments around, got 2"});
    expect_error(head + "    geometry: {type: cylinder, angle: 361}\n", 9,
                 "shells[0].geometry.angle", {"must be in (0, 360], got 361"});
    expect_error(head + "    geometry: {type: cone}\n", 9, "shells[0].geometry.type",
                 {"expected one of sheet, cylinder, sphere, mesh, got 'cone'"});
    expect_error(head + "    geometry: {type: mesh, path: no_such.obj}\n", 9,
                 "shells[0].geometry.path", {"mesh file not found"});
    expect_error(head + "    scale: 1\n", 8, "shells[0].geometry", {"required key 'geometry'"});
    expect_error(head + "    geometry: {type: sheet}\n    output_refine: 5\n", 10,
                 "shells[0].output_refine", {"must be in [0, 4], got 5"});
    expect_error(head + "    geometry: {type: sheet}\n    point_loads: [{index: 0}]\n", 10,
                 "shells[0].point_loads[0].force", {"required key 'force' is missing"});
  }
  SECTION("pre-roll and output") {
    expect_error(kHead + "preroll: {tolerance: 0}\n", 5, "preroll.tolerance", {"must be > 0"});
    expect_error(kHead + "preroll: {max_steps: 0}\n", 5, "preroll.max_steps",
                 {"must be >= 1, got 0"});
    expect_error(kHead + "preroll: {enabled: yes}\n", 5, "preroll.enabled",
                 {"expected true or false"});
    const std::string two = kHead + mats +
                            "shells:\n"
                            "  - {material: cotton, geometry: " +
                            sheet +
                            "}\n"
                            "  - {material: cotton, geometry: " +
                            sheet + "}\n";  // line 10 next
    expect_error(two + "output:\n  shell_pattern: cloth.####.ply\n", 11, "output.shell_pattern",
                 {"must contain {name}", "more than one shell", "'cloth.####.ply'"});
    expect_error(kHead + "output:\n  shell_pattern: \"{name}.ply\"\n", 6, "output.shell_pattern",
                 {"exactly one run of '#'"});
    expect_error(kHead + "output:\n  shell_format: abc\n", 6, "output.shell_format",
                 {"expected one of ply, obj, glb, got 'abc'"});
    // One shell needs no {name}.
    const Scene one = parse_scene(kHead + mats + "shells: [{material: cotton, geometry: " + sheet +
                                      "}]\n" + "output: {shell_pattern: cloth.####.ply}\n",
                                  "scenes/ok.yaml");
    CHECK(one.output.shell_pattern == "cloth.####.ply");
  }
  SECTION("overrides reach shell keys") {
    const std::string text =
        kHead + mats + "shells:\n  - {material: cotton, geometry: " + sheet + "}\n";
    const Scene s =
        parse_scene(text, "scenes/ok.yaml",
                    {"shells[0].geometry.resolution=[3, 4]", "shells.0.pins=[{indices: [19]}]",
                     "shell_materials[0].thickness=0.01", "preroll.enabled=true"});
    CHECK(s.shells[0].resolution[0] == 3);
    CHECK(s.shells[0].pins[0].indices == std::vector<int>{19});  // (3 + 1) * (4 + 1) = 20
    CHECK(s.shell_materials[0].thickness == 0.01);
    CHECK(s.preroll.enabled);
    expect_override_error(text, "shells[0].geometry.resolution=[0, 4]",
                          "shells[0].geometry.resolution[0]", {"must be in [1, 2000]"});
    expect_override_error(text, "shells[0].geometry.radius=1", "shells[0].geometry.radius",
                          {"'radius' is not allowed for type sheet"});
  }
}

TEST_CASE(
    "output.shell_pattern's default extension follows shell_format, a contradicting "
    "one is refused",
    "[scene]") {
  for (const std::string fmt : {"ply", "obj", "glb"}) {
    CAPTURE(fmt);
    const Scene s = parse_scene(kHead + "output:\n  shell_format: " + fmt + "\n", "scenes/ok.yaml");
    CHECK(word_of(s.output.shell_format) == fmt);
    CHECK(s.output.shell_pattern == "{name}.####." + fmt);
    // The same through --set.
    const Scene o = parse_scene(kHead, "scenes/ok.yaml", {"output.shell_format=" + fmt});
    CHECK(o.output.shell_pattern == "{name}.####." + fmt);
    // A given pattern with the format's extension is kept as written.
    const Scene g = parse_scene(kHead + "output:\n  shell_format: " + fmt +
                                    "\n  shell_pattern: \"meshes/{name}_####." + fmt + "\"\n",
                                "scenes/ok.yaml");
    CHECK(g.output.shell_pattern == "meshes/{name}_####." + fmt);
  }
  CHECK(parse_scene(kHead, "scenes/ok.yaml").output.shell_pattern == "{name}.####.ply");

  // glTF in a file named .ply (issue 12, item 10), and the other mismatches: refused at
  // the pattern's line, naming the format and the extension it needs.
  expect_error(kHead + "output:\n  shell_format: glb\n  shell_pattern: \"{name}.####.ply\"\n", 7,
               "output.shell_pattern",
               {"must end in '.glb' for output.shell_format glb", "'{name}.####.ply'"});
  expect_error(kHead + "output:\n  shell_pattern: \"{name}.####.obj\"\n", 6, "output.shell_pattern",
               {"must end in '.ply' for output.shell_format ply"});
  expect_error(kHead + "output:\n  shell_format: obj\n  shell_pattern: \"{name}.####\"\n", 7,
               "output.shell_pattern", {"must end in '.obj'"});
  expect_error(kHead + "output:\n  shell_format: glb\n  shell_pattern: \"{name}.####.GLB\"\n", 7,
               "output.shell_pattern", {"must end in '.glb'"});
  // A format from --set against a pattern in the file: reported at the pattern's line.
  expect_error(kHead + "output:\n  shell_pattern: \"{name}.####.ply\"\n", 6, "output.shell_pattern",
               {"must end in '.glb' for output.shell_format glb"}, {"output.shell_format=glb"});
}

TEST_CASE("output.up_axis: y by default, z when asked, anything else refused at the key",
          "[scene][axes]") {
  CHECK(parse_scene(kHead, "scenes/ok.yaml").output.up_axis == UpAxis::Y);
  CHECK(parse_scene(kHead + "output:\n  up_axis: z\n", "scenes/ok.yaml").output.up_axis ==
        UpAxis::Z);
  CHECK(parse_scene(kHead, "scenes/ok.yaml", {"output.up_axis=z"}).output.up_axis == UpAxis::Z);
  // GLB with Z up is accepted: glTF meshes stay Y-up by definition, the other caches turn.
  CHECK(parse_scene(kHead + "output:\n  up_axis: z\n  shell_format: glb\n", "scenes/ok.yaml")
            .output.up_axis == UpAxis::Z);
  expect_override_error(kHead, "output.up_axis=x", "output.up_axis",
                        {"expected one of y, z, got 'x'"});
  expect_error(kHead + "output:\n  up_axis: Z\n", 6, "output.up_axis",
               {"expected one of y, z, got 'Z'"});
}

TEST_CASE("docs/scene-format.md documents exactly the schema", "[scene]") {
  std::ifstream in(kSource + "/docs/scene-format.md");
  REQUIRE(in);
  std::map<std::string, int> column;  // header name -> index, for the current table
  std::map<std::string, std::vector<std::string>> documented;  // key -> its row
  std::map<std::string, std::map<std::string, int>> columns_of;
  std::string line;
  int tables = 0;
  while (std::getline(in, line)) {
    const std::vector<std::string> cells = split_row(line);
    if (cells.empty()) {
      column.clear();
      continue;
    }
    if (cells[0] == "Key") {
      column.clear();
      for (std::size_t i = 0; i < cells.size(); ++i) column[cells[i]] = static_cast<int>(i);
      ++tables;
      continue;
    }
    if (column.empty() || cells[0].find_first_not_of("-: ") == std::string::npos) continue;
    REQUIRE(cells[0].size() > 2);
    REQUIRE(cells[0].front() == '`');
    REQUIRE(cells[0].back() == '`');
    const std::string key = cells[0].substr(1, cells[0].size() - 2);
    CAPTURE(key);
    CHECK(documented.count(key) == 0);  // each key documented once
    documented[key] = cells;
    columns_of[key] = column;
  }
  CHECK(tables >= 7);

  std::set<std::string> schema_keys;
  for (const KeySpec& s : scene_schema()) {
    CAPTURE(s.key);
    CHECK(schema_keys.insert(s.key).second);
    for (const std::string& text :
         {s.type_text(), s.unit_text(), s.default_text(), s.range_text(), s.only_for_text()}) {
      CHECK(text.find('|') == std::string::npos);  // would break the markdown table
    }
    auto it = documented.find(s.key);
    if (it == documented.end()) {
      FAIL_CHECK("schema key " << s.key << " is not documented in docs/scene-format.md");
      continue;
    }
    const std::vector<std::string>& row = it->second;
    const std::map<std::string, int>& col = columns_of[s.key];
    auto cell = [&](const char* name) -> std::string {
      auto c = col.find(name);
      if (c == col.end() || c->second >= static_cast<int>(row.size())) return "<no column>";
      return row[c->second];
    };
    CHECK(cell("Type") == s.type_text());
    CHECK(cell("Unit") == s.unit_text());
    CHECK(cell("Default") == s.default_text());
    CHECK(cell("Range") == s.range_text());
    if (col.count("Only for")) {
      CHECK(cell("Only for") == s.only_for_text());
    } else {
      CHECK(s.only_for.empty());  // a table without the column holds no type-specific keys
    }
  }
  for (const auto& [key, row] : documented) {
    CAPTURE(key);
    CHECK(schema_keys.count(key) == 1);  // documented keys exist
  }
}

TEST_CASE("schema entries are consistent", "[scene]") {
  for (const KeySpec& s : scene_schema()) {
    CAPTURE(s.key);
    // Required keys have no default; Default keys have one (applied and validated on read).
    CHECK((s.presence == Presence::Required) == s.default_value.empty());
    CHECK((s.type == KeyType::Enum) == !s.choices.empty());
    if (s.unit_vector) CHECK(s.type == KeyType::Vec3);
    if (s.nonempty) CHECK(s.type == KeyType::String);
  }
}

TEST_CASE("scene: shot.integrator implicit and its dt_max default", "[scene]") {
  const std::string shells =
      "shell_materials: [{name: m}]\n"
      "shells:\n"
      "  - {name: s, material: m, geometry: {type: sheet, size: [0.2, 0.2], resolution: [4, "
      "4]}}\n";
  const std::string head = kHead + "  integrator: implicit\n";  // line 5
  {
    const Scene s = parse_scene(head + shells, "scenes/ok.yaml", {});
    CHECK(s.shot.integrator == Integrator::Implicit);
    CHECK(s.shot.dt_max == Approx(1.0 / 24));  // one frame, not the explicit 1e-2
    CHECK(s.shot.implicit_preconditioner == ImplicitPreconditioner::Factorised);
  }
  {
    const Scene s = parse_scene(head + "  dt_max: 0.002\n" + shells, "scenes/ok.yaml", {});
    CHECK(s.shot.dt_max == 0.002);
    const Scene e = parse_scene(kHead + shells, "scenes/ok.yaml", {});
    CHECK(e.shot.integrator == Integrator::Explicit);
    CHECK(e.shot.dt_max == 1e-2);
  }
  // Shells in contact (a collider) are stepped implicitly too, on the grid.
  const Scene c = parse_scene(
      head + shells +
          "colliders:\n  - {shape: {type: plane, point: [0, -1, 0], normal: [0, 1, 0]}}\n",
      "scenes/ok.yaml", {});
  CHECK(c.shot.integrator == Integrator::Implicit);
}

// The "resolved" block of run.json (shot/run_resolved.h): what the Blender loader reads
// instead of the scene's YAML. Frames, fps, axes, the patterns of the caches the run
// writes, shells with their own patterns and colours, and the cameras as the scene gives them.
#include <catch2/catch.hpp>

#include <string>

#include "io/scene_reader.h"
#include "shot/run_resolved.h"

using namespace shellmpm;

namespace {

const char* kScene = R"(version: 1
shot:
  frames: [3, 7]
  fps: 30
  dx: 0.05
  domain: {min: [-0.6, 0, -0.6], max: [0.6, 1.0, 0.6]}
materials:
  - {name: jelly, type: elastic, youngs_modulus: 2.0e4, density: 1000}
sources:
  - {name: block, material: jelly, shape: {type: box, min: [-0.15, 0.3, -0.15], max: [0.15, 0.6, 0.15]}}
shell_materials:
  - {name: cotton, youngs_modulus: 1.0e6, density: 400, thickness: 0.001, front_color: [0.9, 0.8, 0.1]}
shells:
  - {name: cloth, material: cotton, geometry: {type: sheet, size: [0.4, 0.4], resolution: [4, 4]}, translate: [0, 0.8, 0]}
  - {name: flag, material: cotton, geometry: {type: sheet, size: [0.2, 0.2], resolution: [2, 2]}, translate: [0, 0.9, 0]}
output:
  directory: out
  shell_pattern: "meshes/{name}.###.ply"
render:
  size: [320, 180]
  cameras:
    - {name: side, position: [2, 0.5, 0], target: [0, 0.5, 0], fov: 30}
    - {name: front, position: [0, 0.6, 2.0], target: [0, 0.4, 0], up: [0, 1, 0], fov: 45}
  camera: front
)";

std::vector<double> vec(const nlohmann::json& j) {
  return j.get<std::vector<double>>();
}

}  // namespace

TEST_CASE("run.json resolved block: frames, axes, patterns, shells, cameras",
          "[io][run_resolved]") {
  const Scene scene = parse_scene(kScene, "scenes/r.yaml");
  const nlohmann::json j = resolved_run_settings(scene);
  CHECK(j.at("fps").get<double>() == 30.0);
  CHECK(j.at("frames") == nlohmann::json({3, 7}));
  CHECK(j.at("up_axis") == "y");
  CHECK(j.at("size") == nlohmann::json({320, 180}));
  CHECK(j.at("density").at("pattern") == "density.####.vdb");
  CHECK(j.at("density").at("grid") == "density");
  CHECK(j.at("density").at("velocity_grid").is_null());
  CHECK(j.at("density").at("extinction").get<double>() == scene.render.volume_extinction);
  CHECK(j.at("particles").is_null());
  REQUIRE(j.at("shells").size() == 2);
  CHECK(j["shells"][0].at("name") == "cloth");
  CHECK(j["shells"][0].at("pattern") == "meshes/cloth.###.ply");
  CHECK(j["shells"][1].at("pattern") == "meshes/flag.###.ply");
  CHECK(j["shells"][0].at("format") == "ply");
  CHECK(vec(j["shells"][0].at("front_color")) == std::vector<double>{0.9, 0.8, 0.1});
  const Vec3d back = scene.render.shell_back;  // the material has none: the render default
  CHECK(vec(j["shells"][0].at("back_color")) == std::vector<double>{back.x(), back.y(), back.z()});
  REQUIRE(j.at("cameras").size() == 2);
  CHECK(j["cameras"][1].at("name") == "front");
  CHECK(vec(j["cameras"][1].at("position")) == std::vector<double>{0, 0.6, 2.0});
  CHECK(vec(j["cameras"][1].at("target")) == std::vector<double>{0, 0.4, 0});
  CHECK(vec(j["cameras"][0].at("up")) == std::vector<double>{0, 1, 0});
  CHECK(j["cameras"][0].at("fov").get<double>() == 30.0);
  CHECK(j.at("camera") == "front");
  CHECK(vec(j.at("domain").at("min")) == std::vector<double>{-0.6, 0, -0.6});
}

TEST_CASE("run.json resolved block: what the run does not write is null or left out",
          "[io][run_resolved]") {
  // No bulk material: no density volume even though output.density is on; a shell whose
  // mesh is not written is not listed; no cameras: "auto"; velocities name the vel grid.
  const Scene scene = parse_scene(R"(version: 1
shot: {frames: [1, 2], domain: {min: [-1, -1, -1], max: [1, 1, 1]}, dx: 0.1}
shell_materials: [{name: m}]
shells:
  - {name: a, material: m, geometry: {type: sheet, size: [0.4, 0.4], resolution: [2, 2]}}
  - {name: b, material: m, geometry: {type: sheet, size: [0.4, 0.4], resolution: [2, 2]}, translate: [0, 0.5, 0], write_mesh: false}
output: {velocity: true, particles: true}
)",
                                  "scenes/n.yaml");
  const nlohmann::json j = resolved_run_settings(scene);
  CHECK(j.at("density").is_null());
  CHECK(j.at("particles").is_null());
  REQUIRE(j.at("shells").size() == 1);
  CHECK(j["shells"][0].at("name") == "a");
  CHECK(j["shells"][0].at("pattern") == "a.####.ply");
  CHECK(j.at("cameras").empty());
  CHECK(j.at("camera") == "auto");

  Scene bulk = scene;
  bulk.sources.emplace_back();
  const nlohmann::json k = resolved_run_settings(bulk);
  CHECK(k.at("density").at("velocity_grid") == "vel");
  CHECK(k.at("particles").at("pattern") == "particles.####.ply");
}

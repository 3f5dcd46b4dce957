// Shell mesh caches as `shellmpm run` writes them (issue 12, items 10 and 11): the file
// names follow output.shell_format, and with output.velocity the vertices carry their
// velocity (PLY vx vy vz, GLB _VELOCITY), deterministic and consistent with the motion.
#include <catch2/catch.hpp>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/app/cli_harness.h"
#include "tests/support/ply_cache.h"

namespace fs = std::filesystem;
using namespace shellmpm_test;

namespace {

// A free sheet drifting at a constant velocity without gravity, three frames at 24 fps.
const char* kScene = R"(version: 1
shot:
  frames: [1, 3]
  fps: 24
  dx: 0.05
  gravity: [0, 0, 0]
  domain: {min: [-1, -1, -1], max: [1, 1, 1]}
shell_materials:
  - {name: cotton, youngs_modulus: 2.0e4, poisson_ratio: 0.3, density: 400, thickness: 0.001}
shells:
  - name: cloth
    material: cotton
    geometry: {type: sheet, size: [0.5, 0.4], resolution: [10, 8]}
    output_refine: 1
    velocity: [0.3, -0.2, 0.1]
output:
  directory: OUT
  density: false
)";
const Eigen::Vector3d kVelocity(0.3, -0.2, 0.1);
const double kFrameDt = 1.0 / 24;

std::string write_scene(const TempDir& d, const std::string& extra_output = "") {
  std::string t = kScene;
  t.replace(t.find("OUT"), 3, d.file("out"));
  return d.write("drift.yaml", t + extra_output);
}

std::string run_into(const std::string& scene, const std::string& out,
                     const std::string& sets = "") {
  const CmdResult r = run_shellmpm("run " + scene + " -q -o " + out + " " + sets);
  INFO(r.output);
  REQUIRE(r.code == 0);
  return out;
}

nlohmann::json glb_json(const std::string& bytes, std::size_t& bin_offset) {
  REQUIRE(bytes.size() > 20);
  std::uint32_t json_len = 0;
  std::memcpy(&json_len, bytes.data() + 12, 4);
  REQUIRE(20 + json_len + 8 <= bytes.size());
  bin_offset = 20 + json_len + 8;
  return nlohmann::json::parse(bytes.substr(20, json_len));
}

}  // namespace

TEST_CASE("run: shell mesh velocities equal the motion, every run the same", "[cli][velocity]") {
  TempDir d("cli_mesh_velocity");
  const std::string scene = write_scene(d, "  velocity: true\n");
  const std::string a = run_into(scene, d.file("a")), b = run_into(scene, d.file("b"));

  std::vector<TriMesh> frames;
  for (int f = 1; f <= 3; ++f) {
    const std::string name = "cloth.000" + std::to_string(f) + ".ply";
    CAPTURE(name);
    REQUIRE(fs::exists(a + "/" + name));
    // Deterministic: the same bytes in a second run.
    CHECK(read_text(a + "/" + name) == read_text(b + "/" + name));
    frames.push_back(read_mesh_ply(a + "/" + name));
    const TriMesh& m = frames.back();
    REQUIRE(!m.x.empty());
    REQUIRE(m.v.size() == m.x.size());  // one velocity per vertex, same count and order
    CHECK(m.vertex_properties ==
          std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz", "s", "t", "vx", "vy", "vz"});
  }
  REQUIRE(frames[0].x.size() == frames[2].x.size());
  // Every vertex moves at the sheet's velocity, and its velocity is the finite difference
  // of its positions over a frame.
  double to_velocity = 0, to_difference = 0, moved = 0;
  for (int f = 0; f < 3; ++f)
    for (std::size_t i = 0; i < frames[f].v.size(); ++i) {
      to_velocity = std::max(to_velocity, (frames[f].v[i] - kVelocity).norm());
      if (f == 0) continue;
      const Eigen::Vector3d fd = (frames[f].x[i] - frames[f - 1].x[i]) / kFrameDt;
      to_difference = std::max(to_difference, (fd - frames[f].v[i]).norm());
      moved = std::max(moved, (frames[f].x[i] - frames[f - 1].x[i]).norm());
    }
  INFO("max |v - shells[0].velocity| " << to_velocity << " m/s; max |dx/dt - v| " << to_difference
                                       << " m/s");
  CHECK(moved > 0.01);  // it did move (0.37 m/s for 1/24 s)
  // Measured: 4e-8 m/s at frame 1 (the float rounding of the velocity), 1.05e-5 m/s from
  // frame 2 on (float rounding noise in the elastic forces of the drifting sheet nudges the
  // control points), and 9.1e-6 m/s between dx/dt and v. A velocity off by a frame's
  // acceleration or a misplaced vertex would be off by more than 0.01 m/s.
  CHECK(to_velocity < 1e-4);
  CHECK(to_difference < 1e-4);
}

TEST_CASE("run: without output.velocity meshes have no velocity properties", "[cli][velocity]") {
  TempDir d("cli_mesh_novelocity");
  const std::string out = run_into(write_scene(d), d.file("out"), "--frames 1-1");
  const TriMesh m = read_mesh_ply(out + "/cloth.0001.ply");
  REQUIRE(!m.x.empty());
  CHECK(m.v.empty());
  CHECK(m.vertex_properties == std::vector<std::string>{"x", "y", "z", "nx", "ny", "nz", "s", "t"});
}

TEST_CASE("run: shell_format glb writes .glb files with _VELOCITY per vertex", "[cli][velocity]") {
  TempDir d("cli_mesh_glb");
  const std::string out = run_into(write_scene(d, "  velocity: true\n  shell_format: glb\n"),
                                   d.file("out"), "--frames 1-2");
  CHECK_FALSE(fs::exists(out + "/cloth.0001.ply"));
  for (const char* name : {"cloth.0001.glb", "cloth.0002.glb"}) {
    CAPTURE(name);
    REQUIRE(fs::exists(out + "/" + name));
    const std::string bytes = read_text(out + "/" + name);
    CHECK(bytes.compare(0, 4, "glTF") == 0);
    std::size_t bin = 0;
    const nlohmann::json j = glb_json(bytes, bin);
    const nlohmann::json& attrs = j["meshes"][0]["primitives"][0]["attributes"];
    REQUIRE(attrs.contains("_VELOCITY"));
    const nlohmann::json& pos = j["accessors"][attrs["POSITION"].get<int>()];
    const nlohmann::json& vel = j["accessors"][attrs["_VELOCITY"].get<int>()];
    const std::size_t n = pos["count"].get<std::size_t>();
    CHECK(n > 100);
    CHECK(vel["count"].get<std::size_t>() == n);
    CHECK(vel["type"] == "VEC3");
    CHECK(vel["componentType"] == 5126);
    const nlohmann::json& view = j["bufferViews"][vel["bufferView"].get<int>()];
    REQUIRE(view["byteLength"].get<std::size_t>() == 12 * n);
    const std::size_t at = bin + view["byteOffset"].get<std::size_t>();
    REQUIRE(at + 12 * n <= bytes.size());
    double worst = 0;
    for (std::size_t i = 0; i < n; ++i) {
      float v[3];
      std::memcpy(v, bytes.data() + at + 12 * i, 12);
      worst = std::max(worst, (Eigen::Vector3d(v[0], v[1], v[2]) - kVelocity).norm());
    }
    INFO("max |v - shells[0].velocity| " << worst);
    CHECK(worst < 1e-4);  // measured 1.05e-5 m/s at frame 2 (see the PLY case)
  }
}

TEST_CASE("check: a shell pattern whose extension contradicts shell_format exits 2", "[cli]") {
  TempDir d("cli_mesh_pattern");
  const std::string scene =
      write_scene(d, "  shell_format: glb\n  shell_pattern: \"{name}.####.ply\"\n");
  const CmdResult r = run_shellmpm("check " + scene);
  INFO(r.output);
  CHECK(r.code == 2);
  // The pattern is on line 20 of the scene.
  CHECK(r.output.find(scene + ":20: output.shell_pattern: must end in '.glb'") !=
        std::string::npos);
}

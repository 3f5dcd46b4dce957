// `shellmpm render` and `shellmpm run --preview` end to end: outputs, determinism, and
// errors for bad input and for missing or corrupt caches.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "render/image.h"
#include "render/preview_job.h"
#include "tests/app/cli_harness.h"

using namespace shellmpm_test;
namespace fs = std::filesystem;

namespace {

// Jelly falling next to a small pinned cloth: density volumes, a particle cache and a
// shell mesh per frame, in a few seconds.
const char* kScene = R"(version: 1
shot:
  frames: [1, 3]
  fps: 24
  dx: 0.05
  domain: {min: [-0.6, 0, -0.6], max: [0.6, 1.0, 0.6]}
materials:
  - {name: jelly, type: elastic, youngs_modulus: 2.0e4, density: 1000}
sources:
  - {name: block, material: jelly, shape: {type: box, min: [-0.15, 0.3, -0.15], max: [0.15, 0.6, 0.15]}, particles_per_cell: 4}
colliders:
  - {name: ground, shape: {type: plane, point: [0, 0.1, 0], normal: [0, 1, 0]}}
  - {name: ball, shape: {type: sphere, center: [0.3, 0.25, 0.2], radius: 0.12}}
shell_materials:
  - {name: cotton, youngs_modulus: 1.0e6, density: 400, thickness: 0.001, front_color: [0.9, 0.8, 0.1]}
shells:
  - name: cloth
    material: cotton
    geometry: {type: sheet, size: [0.4, 0.4], resolution: [6, 6]}
    translate: [-0.3, 0.7, 0]
    pins: [{indices: [0, 6]}]
output:
  directory: out/never_used
  particles: true
render:
  size: [160, 90]
  cameras:
    - {name: front, position: [0, 0.6, 2.0], target: [0, 0.4, 0], fov: 45}
)";

struct RunDir {
  TempDir dir;
  std::string out;
  explicit RunDir(const std::string& name) : dir(name) {
    const std::string scene = dir.write("scene.yaml", kScene);
    out = dir.file("out");
    const CmdResult r = run_shellmpm("run " + scene + " -q --threads 2 -o " + out);
    INFO(r.output);
    REQUIRE(r.code == 0);
  }
};

}  // namespace

TEST_CASE("render: a run's frames, contact sheet, deterministic bytes", "[render][cli]") {
  RunDir run("render_cli");
  REQUIRE(fs::exists(run.out + "/run.json"));
  for (const char* renderer : {"raster", "raytrace"}) {
    CAPTURE(renderer);
    const CmdResult r = run_shellmpm("render " + run.out + " --threads 2 --renderer " + renderer);
    INFO(r.output);
    REQUIRE(r.code == 0);
    for (int f = 1; f <= 3; ++f) {
      const shellmpm::Image im =
          shellmpm::read_png(run.out + "/preview.000" + std::to_string(f) + ".png");
      CHECK(im.width == 160);
      CHECK(im.height == 90);
    }
    CHECK(fs::exists(run.out + "/contact_sheet.png"));
    // The MP4 is written, or skipped with a message, depending on ffmpeg.
    CHECK(r.output.find("preview.mp4") != std::string::npos);
    CHECK(fs::exists(run.out + "/preview.mp4") == !shellmpm::find_ffmpeg().empty());
    const std::string first = read_text(run.out + "/preview.0002.png");
    const CmdResult again = run_shellmpm(
        "render " + run.out + " -q --threads 1 --frames 2 --renderer " + std::string(renderer));
    REQUIRE(again.code == 0);
    CHECK(read_text(run.out + "/preview.0002.png") == first);
  }
  // Options: size, camera, a scene override; the named camera differs from auto.
  const CmdResult c =
      run_shellmpm("render " + run.out + " -q --frames 1 --camera front --size 64x48");
  INFO(c.output);
  REQUIRE(c.code == 0);
  const shellmpm::Image im = shellmpm::read_png(run.out + "/preview.0001.png");
  CHECK(im.width == 64);
  CHECK(im.height == 48);
}

TEST_CASE("render: a missing or corrupt cache names the file, the other frames still render",
          "[render][cli]") {
  RunDir run("render_cli_bad");
  fs::remove(run.out + "/density.0002.vdb");    // the ray tracer marches the volume
  fs::remove(run.out + "/particles.0002.ply");  // raster draws the particle cache
  std::ofstream(run.out + "/cloth.0003.ply", std::ios::binary)
      << "ply\nformat binary_little_endian 1.0\n"
         "element vertex 100\nproperty float x\n"
         "property float y\nproperty float z\n"
         "end_header\nshort";
  for (const char* renderer : {"raster", "raytrace"}) {
    for (int f = 1; f <= 3; ++f) fs::remove(run.out + "/preview.000" + std::to_string(f) + ".png");
    const CmdResult r = run_shellmpm("render " + run.out + " --renderer " + renderer);
    INFO(r.output);
    CHECK(r.code == 1);
    CHECK(r.output.find(std::string(renderer) == "raster"
                            ? "particles.0002.ply: missing"
                            : "density.0002.vdb: missing") != std::string::npos);
    CHECK(r.output.find("cloth.0003.ply: truncated") != std::string::npos);
    CHECK(fs::exists(run.out + "/preview.0001.png"));
    CHECK_FALSE(fs::exists(run.out + "/preview.0002.png"));
    CHECK_FALSE(fs::exists(run.out + "/preview.0003.png"));
  }
  // A VDB that is not one, and a particle cache cut short.
  std::ofstream(run.out + "/density.0001.vdb", std::ios::binary) << "not a vdb file at all";
  const CmdResult v = run_shellmpm("render " + run.out + " --frames 1 --renderer raytrace");
  INFO(v.output);
  CHECK(v.code == 1);
  CHECK(v.output.find("density.0001.vdb: unreadable VDB") != std::string::npos);
  fs::resize_file(run.out + "/particles.0001.ply", 300);
  const CmdResult p = run_shellmpm("render " + run.out + " --frames 1 --set render.bulk=particles");
  INFO(p.output);
  CHECK(p.code == 1);
  CHECK(p.output.find("particles.0001.ply: truncated") != std::string::npos);
}

TEST_CASE("render: bad input is refused with exit code 2 and a message naming it",
          "[render][cli]") {
  TempDir d("render_cli_input");
  auto expect = [](const std::string& args, const std::string& text) {
    const CmdResult r = run_shellmpm(args);
    INFO(args << "\n" << r.output);
    CHECK(r.code == 2);
    CHECK(r.output.find(text) != std::string::npos);
  };
  expect("render " + d.file("nowhere"), "nowhere: no such directory");
  expect("render " + d.path.string(), "run.json: not found");
  d.write("run.json", "{\"format\": \"something else\"}");
  expect("render " + d.path.string(), "not a shellmpm run manifest");
  d.write("run.json", "{ broken json");
  expect("render " + d.path.string(), "corrupt run manifest");
  RunDir run("render_cli_input_run");
  expect("render " + run.out + " --size 10x10",
         "--size 10x10: width and height must be in [16, 8192]");
  expect("render " + run.out + " --size big", "--size big: expected WxH");
  expect("render " + run.out + " --camera side",
         "--camera side: unknown camera (cameras: auto, front)");
  expect("render " + run.out + " --renderer vulkan", "--renderer");
  expect("render " + run.out + " --frames 3-1", "--frames 3-1: need 1 <= A <= B");
  expect("render " + run.out + " --set render.size=[8,8]", "render.size[0]: must be in [16, 8192]");
  expect("render " + run.out + " --set render.shell_front=[2,0,0]",
         "render.shell_front[0]: a colour component must be in [0, 1]");
  expect("render " + run.out + " --set render.camera=top", "render.camera: unknown camera 'top'");
  expect("render " + run.out + " --set output.particles=false --set render.bulk=particles",
         "render.bulk: 'particles' draws the particle cache, but the run writes none");
}

TEST_CASE("run --preview renders each frame as it is written", "[render][cli]") {
  TempDir d("run_preview");
  const std::string scene = d.write("scene.yaml", kScene);
  const CmdResult r =
      run_shellmpm("run " + scene + " --threads 2 --frames 1-2 --preview -o " + d.file("o"));
  INFO(r.output);
  REQUIRE(r.code == 0);
  CHECK(fs::exists(d.file("o/preview.0001.png")));
  CHECK(fs::exists(d.file("o/preview.0002.png")));
  CHECK(fs::exists(d.file("o/contact_sheet.png")));
  CHECK_FALSE(fs::exists(d.file("o/preview.0003.png")));
  // The same frame rendered later from the caches is the same image.
  const std::string during = read_text(d.file("o/preview.0002.png"));
  const CmdResult again = run_shellmpm("render " + d.file("o") + " -q --frames 2 --threads 2");
  REQUIRE(again.code == 0);
  CHECK(read_text(d.file("o/preview.0002.png")) == during);
}

TEST_CASE("render: previews are the same bytes whatever output.up_axis says",
          "[render][cli][axes]") {
  TempDir dir("render_up_axis");
  const std::string scene = dir.write("scene.yaml", kScene);
  const std::string y = dir.file("y"), z = dir.file("z");
  for (const std::string& axis : {std::string("y"), std::string("z")}) {
    const CmdResult r = run_shellmpm("run " + scene + " -q --threads 2 --frames 1-2 -o " +
                                     dir.file(axis) + " --set output.up_axis=" + axis);
    INFO(r.output);
    REQUIRE(r.code == 0);
  }
  // The caches differ (Z-up holds them turned), so equal previews mean the renderer turned
  // them back.
  for (const char* cache : {"/density.0002.vdb", "/particles.0002.ply", "/cloth.0002.ply"}) {
    CAPTURE(cache);
    CHECK(read_text(y + cache) != read_text(z + cache));
  }
  for (const std::string renderer : {"raster", "raytrace"})
    for (const std::string bulk : {"", " --set render.bulk=surface"}) {
      CAPTURE(renderer, bulk);
      for (const std::string& out : {y, z}) {
        const CmdResult r =
            run_shellmpm("render " + out + " -q --threads 2 --renderer " + renderer + bulk);
        INFO(r.output);
        REQUIRE(r.code == 0);
      }
      for (const char* png : {"/preview.0001.png", "/preview.0002.png"}) {
        CAPTURE(png);
        const std::string a = read_text(y + png), b = read_text(z + png);
        REQUIRE(!a.empty());
        CHECK(a == b);
      }
    }
}

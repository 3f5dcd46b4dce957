// The Blender loader (tools/blender/shellmpm_import.py) end to end, with Debian's
// `blender -b` when it is installed (tools/install-blender.sh; SHELLMPM_BLENDER names
// another binary): a tiny run with a sheet and a jelly block is loaded and rendered with
// Cycles twice, with the density volume shown and hidden. The image must not be blank, the
// volume must change the pixels where it is, and Blender's mesh and frame range must be
// the run's. With `--bulk surface` the block is the density's iso-surface: a mesh where
// OpenVDB's volumeToMesh (the preview's) puts it, opaque in the render, unlike the fog.
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "render/image.h"
#include "tests/app/cli_harness.h"
#include "tests/support/ply_cache.h"

using namespace shellmpm_test;

namespace {

/// The Blender binary: $SHELLMPM_BLENDER, else `blender` on PATH; empty when there is none.
std::string find_blender() {
  if (const char* env = std::getenv("SHELLMPM_BLENDER"); env && *env)
    return ::access(env, X_OK) == 0 ? env : "";
  const char* path = std::getenv("PATH");
  if (!path) return "";
  std::stringstream ss(path);
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    if (dir.empty()) continue;
    const std::string f = dir + "/blender";
    if (::access(f.c_str(), X_OK) == 0) return f;
  }
  return "";
}

// A jelly block falling in front of a pinned cloth that hangs above it: one shell mesh
// sequence and a density volume, three frames at 24 fps, seen from the front camera.
const char* kScene = R"(version: 1
shot:
  frames: [1, 3]
  fps: 24
  dx: 0.05
  domain: {min: [-0.6, 0, -0.6], max: [0.6, 1.0, 0.6]}
materials:
  - {name: jelly, type: elastic, youngs_modulus: 2.0e4, density: 1000}
sources:
  - {name: block, material: jelly, shape: {type: box, min: [-0.1, 0.25, 0.0], max: [0.15, 0.5, 0.25]}, particles_per_cell: 4}
colliders:
  - {name: ground, shape: {type: plane, point: [0, 0.1, 0], normal: [0, 1, 0]}}
shell_materials:
  - {name: cotton, youngs_modulus: 1.0e6, density: 400, thickness: 0.001, front_color: [0.9, 0.8, 0.1]}
shells:
  - name: cloth
    material: cotton
    geometry: {type: sheet, size: [0.5, 0.4], resolution: [10, 8]}
    translate: [-0.1, 0.75, -0.2]
    rotate: [20, 0, 0]
    pins: [{indices: [0, 10]}]
render:
  size: [160, 90]
  cameras:
    - {name: front, position: [0, 0.9, 2.0], target: [0, 0.45, 0], fov: 40}
)";

struct Render {
  nlohmann::json summary;
  shellmpm::Image image;
  double seconds = 0;
};

/// Loads `rundir` in Blender at `frame` and renders it (with `extra` loader flags).
Render blender_render(const std::string& blender, const std::string& script,
                      const std::string& rundir, const std::string& stem,
                      const std::string& extra) {
  const std::string png = stem + ".png", json = stem + ".json";
  const auto t0 = std::chrono::steady_clock::now();
  const CmdResult r =
      run_command("timeout 600 " + blender + " -b --factory-startup --python-exit-code 3 -P " +
                  script + " -- " + rundir + " --frame 3 --samples 16 --threads 2" + " --render " +
                  png + " --summary " + json + " " + extra);
  Render out;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  INFO(r.output);
  REQUIRE(r.code == 0);
  out.summary = nlohmann::json::parse(read_text(json));
  out.image = shellmpm::read_png(png);
  return out;
}

/// Mean of the pixels' RGB values in [0, 1] over the box [x0, x1) x [y0, y1), and their
/// variance about it, of `a`; with `b`, of |a - b| instead.
struct Stats {
  double mean = 0, variance = 0;
  int pixels = 0;
};
Stats pixel_stats(const shellmpm::Image& a, const shellmpm::Image* b, int x0, int y0, int x1,
                  int y1) {
  Stats s;
  double sum = 0, sum2 = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      for (int c = 0; c < 3; ++c) {
        double v = a.pixel(x, y)[c] / 255.0;
        if (b) v = std::abs(v - b->pixel(x, y)[c] / 255.0);
        sum += v;
        sum2 += v * v;
        ++s.pixels;
      }
  if (s.pixels == 0) return s;
  s.mean = sum / s.pixels;
  s.variance = sum2 / s.pixels - s.mean * s.mean;
  s.pixels /= 3;
  return s;
}

/// Pixels of the box [x0, x1) x [y0, y1) where some channel of `a` and `b` differs by more
/// than `threshold` (in [0, 1]).
int changed_pixels(const shellmpm::Image& a, const shellmpm::Image& b, int x0, int y0, int x1,
                   int y1, double threshold) {
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      int d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(a.pixel(x, y)[c] - b.pixel(x, y)[c]));
      if (d > threshold * 255) ++n;
    }
  return n;
}

/// The box [x0, x1) x [y0, y1) of whole pixels covering an image box [x_min, y_min, x_max,
/// y_max] of the loader's summary, clamped to the image.
struct PixelBox {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  int area() const { return std::max(0, x1 - x0) * std::max(0, y1 - y0); }
};
PixelBox pixel_box(const nlohmann::json& box, const shellmpm::Image& image) {
  const std::vector<double> b = box;
  PixelBox p;
  p.x0 = std::clamp(static_cast<int>(std::floor(b[0])), 0, image.width);
  p.y0 = std::clamp(static_cast<int>(std::floor(b[1])), 0, image.height);
  p.x1 = std::clamp(static_cast<int>(std::ceil(b[2])), 0, image.width);
  p.y1 = std::clamp(static_cast<int>(std::ceil(b[3])), 0, image.height);
  return p;
}

/// Runs kScene into `dir`/out (three frames); returns the run folder.
std::string run_scene(const TempDir& dir) {
  const std::string scene = dir.write("scene.yaml", kScene);
  const std::string out = dir.file("out");
  const CmdResult r = run_shellmpm("run " + scene + " -q --threads 2 -o " + out);
  INFO(r.output);
  REQUIRE(r.code == 0);
  return out;
}

/// OpenVDB's iso-surface of a density VDB (the preview renderer's volumeToMesh, adaptivity
/// 0): its box in the caches' coordinates, and the grid's voxel size.
struct IsoSurface {
  Eigen::Vector3d lo, hi;
  double voxel = 0;
  std::size_t vertices = 0, faces = 0;
};
IsoSurface openvdb_iso_surface(const std::string& path, double iso) {
  openvdb::initialize();
  openvdb::io::File f(path);
  f.open();
  const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid("density"));
  f.close();
  REQUIRE(grid);
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> tris;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*grid, points, tris, quads, iso);
  IsoSurface s;
  s.voxel = grid->voxelSize()[0];
  s.vertices = points.size();
  s.faces = tris.size() + quads.size();
  REQUIRE(!points.empty());
  s.lo = s.hi = Eigen::Vector3d(points[0][0], points[0][1], points[0][2]);
  for (const auto& q : points) {
    const Eigen::Vector3d p(q[0], q[1], q[2]);
    s.lo = s.lo.cwiseMin(p), s.hi = s.hi.cwiseMax(p);
  }
  return s;
}

}  // namespace

TEST_CASE("blender loader: Cycles renders the sheet and the density volume of a run",
          "[slow][blender]") {
  const std::string blender = find_blender();
  if (blender.empty()) {
    WARN(
        "blender is not installed (not on PATH, SHELLMPM_BLENDER unset): the Blender "
        "loader test is skipped; tools/install-blender.sh installs Debian's blender");
    return;
  }
  const std::string script = std::string(SHELLMPM_SOURCE_DIR) + "/tools/blender/shellmpm_import.py";
  TempDir dir("blender_loader");
  const auto t0 = std::chrono::steady_clock::now();
  const std::string out = run_scene(dir);
  const double run_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const Render shown = blender_render(blender, script, out, dir.file("shown"), "");
  const Render hidden = blender_render(blender, script, out, dir.file("hidden"), "--hide-volume");

  // Blender's scene is the run's: frame range, fps, the mesh of frame 3 vertex for vertex.
  const nlohmann::json manifest = nlohmann::json::parse(read_text(out + "/run.json"));
  const nlohmann::json& s = shown.summary;
  CHECK(s.at("frames") == manifest.at("frames"));
  CHECK(s.at("frames") == nlohmann::json({1, 3}));
  CHECK(s.at("fps").get<double>() == Approx(24.0));
  CHECK(s.at("frame") == 3);
  CHECK(s.at("up_axis") == "y");
  CHECK(s.at("camera") == "front");
  REQUIRE(s.at("shells").size() == 1);
  const nlohmann::json& sh = s["shells"][0];
  const TriMesh first = read_mesh_ply(out + "/cloth.0001.ply");
  const TriMesh last = read_mesh_ply(out + "/cloth.0003.ply");
  CHECK(sh.at("vertices").get<std::size_t>() == last.x.size());
  CHECK(sh.at("triangles").get<std::size_t>() == last.tri.size());
  CHECK(sh.at("loaded_frame") == 3);
  const bool ply_uvs = std::find(last.vertex_properties.begin(), last.vertex_properties.end(),
                                 "s") != last.vertex_properties.end();
  CHECK(sh.at("uvs").get<bool>() == ply_uvs);
  // The Y-up cache turned Z up: Blender (x, y, z) = cache (x, -z, y). The handler loaded
  // frame 3, whose box differs from frame 1's (the cloth falls).
  Eigen::Vector3d lo = last.x[0], hi = last.x[0], lo1 = first.x[0];
  for (const auto& p : last.x) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  for (const auto& p : first.x) lo1 = lo1.cwiseMin(p);
  REQUIRE(std::abs(lo1.y() - lo.y()) > 1e-3);
  const std::vector<double> wmin = sh.at("world_min"), wmax = sh.at("world_max");
  CHECK(wmin[0] == Approx(lo.x()).margin(1e-5));
  CHECK(wmin[1] == Approx(-hi.z()).margin(1e-5));
  CHECK(wmin[2] == Approx(lo.y()).margin(1e-5));
  CHECK(wmax[0] == Approx(hi.x()).margin(1e-5));
  CHECK(wmax[1] == Approx(-lo.z()).margin(1e-5));
  CHECK(wmax[2] == Approx(hi.y()).margin(1e-5));
  // The volume sequence: frames 1-3 on files 1-3, the density grid.
  const nlohmann::json& vol = s.at("volume");
  REQUIRE(vol.is_object());
  CHECK(vol.at("frame_start") == 1);
  CHECK(vol.at("frame_offset") == 0);
  CHECK(vol.at("frame_duration") == 3);
  CHECK(vol.at("hidden") == false);
  CHECK(hidden.summary.at("volume").at("hidden") == true);
  const std::vector<std::string> grids = vol.at("grids");
  CHECK(std::find(grids.begin(), grids.end(), "density") != grids.end());

  // The images: the scene's size, not blank.
  const shellmpm::Image& a = shown.image;
  const shellmpm::Image& b = hidden.image;
  REQUIRE(a.width == 160);
  REQUIRE(a.height == 90);
  REQUIRE(b.width == a.width);
  REQUIRE(b.height == a.height);
  const Stats all = pixel_stats(a, nullptr, 0, 0, a.width, a.height);
  // The volume changes the image where it is (its box as seen from the camera) and hardly
  // anywhere else.
  const std::vector<double> box = vol.at("image_box");
  const int x0 = std::clamp(static_cast<int>(std::floor(box[0])), 0, a.width);
  const int y0 = std::clamp(static_cast<int>(std::floor(box[1])), 0, a.height);
  const int x1 = std::clamp(static_cast<int>(std::ceil(box[2])), 0, a.width);
  const int y1 = std::clamp(static_cast<int>(std::ceil(box[3])), 0, a.height);
  const Stats in_box = pixel_stats(a, &b, x0, y0, x1, y1);
  const Stats everywhere = pixel_stats(a, &b, 0, 0, a.width, a.height);
  const double outside_mean = (everywhere.mean * everywhere.pixels - in_box.mean * in_box.pixels) /
                              std::max(1, everywhere.pixels - in_box.pixels);
  const int changed_in = changed_pixels(a, b, x0, y0, x1, y1, 0.1);
  const int changed_all = changed_pixels(a, b, 0, 0, a.width, a.height, 0.1);
  const double total_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ostringstream figures;
  figures << "image variance " << all.variance << "; volume box [" << x0 << ", " << x1 << ") x ["
          << y0 << ", " << y1 << "): mean |shown - hidden| " << in_box.mean << " inside, "
          << outside_mean << " outside, " << changed_in << " pixels changed by > 0.1 inside, "
          << changed_all - changed_in << " outside; run " << run_seconds << " s, Blender "
          << shown.seconds << " s + " << hidden.seconds << " s, total " << total_seconds << " s";
  INFO(figures.str());
  // A blank render (the uniform world alone) has variance 0; this one about 2e-3.
  CHECK(all.variance > 5e-4);
  REQUIRE(in_box.pixels >= 50);
  // The jelly block covers about 25 x 25 pixels of the box (about 60 x 56).
  CHECK(changed_in >= 150);
  CHECK(changed_all - changed_in <= 5);
  CHECK(in_box.mean > 0.005);
  CHECK(in_box.mean > 20 * outside_mean);
  // Reported (pass or fail) so that the figures are in the test log.
  WARN("blender loader: " << figures.str());
}

TEST_CASE("blender loader: --bulk surface renders the density's iso-surface, opaque",
          "[slow][blender]") {
  const std::string blender = find_blender();
  if (blender.empty()) {
    WARN(
        "blender is not installed (not on PATH, SHELLMPM_BLENDER unset): the Blender "
        "loader's --bulk surface test is skipped; tools/install-blender.sh installs it");
    return;
  }
  const std::string script = std::string(SHELLMPM_SOURCE_DIR) + "/tools/blender/shellmpm_import.py";
  TempDir dir("blender_surface");
  const auto t0 = std::chrono::steady_clock::now();
  const std::string out = run_scene(dir);

  const Render surface =
      blender_render(blender, script, out, dir.file("surface"), "--bulk surface");
  const Render bare =
      blender_render(blender, script, out, dir.file("bare"), "--bulk surface --hide-volume");
  const Render fog = blender_render(blender, script, out, dir.file("fog"), "");

  // The surface object: Volume to Mesh on the density grid at the preview's iso level, a
  // mesh with triangles at frame 3; the fog is its source, left out of the render.
  const nlohmann::json& s = surface.summary;
  CHECK(s.at("frame") == 3);
  REQUIRE(s.at("volume").is_object());
  REQUIRE(s.at("surface").is_object());
  CHECK(fog.summary.at("surface").is_null());
  const nlohmann::json& surf = s["surface"];
  CHECK(surf.at("source") == s["volume"].at("object"));
  CHECK(surf.at("grid") == "density");
  CHECK(surf.at("threshold").get<double>() == Approx(0.5));
  CHECK(surf.at("resolution_mode") == "GRID");
  CHECK(surf.at("hidden") == false);
  CHECK(s["volume"].at("hidden") == true);
  CHECK(bare.summary.at("surface").at("hidden") == true);
  CHECK(bare.summary.at("volume").at("hidden") == true);
  REQUIRE(surf.at("triangles").get<int>() > 0);
  CHECK(surf.at("vertices").get<int>() > 0);
  CHECK(surf.at("triangles").get<int>() >= surf.at("faces").get<int>());

  // Where the surface is: OpenVDB's own volumeToMesh of frame 3's density (what the preview
  // draws) gives the same box, turned Z up (Blender (x, y, z) = cache (x, -z, y)), once the
  // loader has moved Blender's voxels back by the half voxel Blender adds (without that
  // shift every side is off by half a voxel).
  const IsoSurface iso = openvdb_iso_surface(out + "/density.0003.vdb", 0.5);
  const double h = iso.voxel;
  REQUIRE(h > 0);
  const std::vector<double> shift = s["volume"].at("location");
  for (double v : shift) CHECK(v == Approx(-0.5 * h).margin(1e-6));
  // Vertex for vertex OpenVDB's mesh (adaptivity 0): the same counts.
  CHECK(surf.at("vertices").get<std::size_t>() == iso.vertices);
  CHECK(surf.at("faces").get<std::size_t>() == iso.faces);
  const std::vector<double> wmin = surf.at("world_min"), wmax = surf.at("world_max");
  const Eigen::Vector3d bmin(wmin[0], wmin[1], wmin[2]), bmax(wmax[0], wmax[1], wmax[2]);
  const Eigen::Vector3d vmin(iso.lo.x(), -iso.hi.z(), iso.lo.y());
  const Eigen::Vector3d vmax(iso.hi.x(), -iso.lo.z(), iso.hi.y());
  const double box_error =
      std::max((bmin - vmin).cwiseAbs().maxCoeff(), (bmax - vmax).cwiseAbs().maxCoeff());
  // And inside the jelly block of the scene (x in [-0.1, 0.15], z in [0, 0.25], Blender's
  // y = -z), between the ground (y 0.1) and the block's top (y 0.5) as it falls, give or
  // take the density's spread (the particles' kernel, about a voxel).
  const Eigen::Vector3d block_min(-0.1, -0.25, 0.1), block_max(0.15, 0.0, 0.5);
  const double outside_block = std::max((block_min - bmin).cwiseMax(0.0).maxCoeff(),
                                        (bmax - block_max).cwiseMax(0.0).maxCoeff());

  // The images: the surface changes the pixels where it is and nowhere else; against the
  // fog it is opaque and smooth where the fog is translucent and noisy, so the pixels in
  // its box differ from the fog's.
  const shellmpm::Image& a = surface.image;
  const shellmpm::Image& b = bare.image;
  const shellmpm::Image& f = fog.image;
  REQUIRE(a.width == 160);
  REQUIRE(a.height == 90);
  REQUIRE(b.width == a.width);
  REQUIRE(b.height == a.height);
  REQUIRE(f.width == a.width);
  REQUIRE(f.height == a.height);
  const PixelBox box = pixel_box(surf.at("image_box"), a);
  REQUIRE(box.area() >= 50);
  const Stats shown_in = pixel_stats(a, &b, box.x0, box.y0, box.x1, box.y1);
  const int changed_in = changed_pixels(a, b, box.x0, box.y0, box.x1, box.y1, 0.1);
  const int changed_all = changed_pixels(a, b, 0, 0, a.width, a.height, 0.1);
  const Stats vs_fog = pixel_stats(a, &f, box.x0, box.y0, box.x1, box.y1);
  const int fog_changed_in = changed_pixels(a, f, box.x0, box.y0, box.x1, box.y1, 0.1);
  const Stats surface_in = pixel_stats(a, nullptr, box.x0, box.y0, box.x1, box.y1);
  const Stats fog_in = pixel_stats(f, nullptr, box.x0, box.y0, box.x1, box.y1);
  const Stats bare_in = pixel_stats(b, nullptr, box.x0, box.y0, box.x1, box.y1);
  const double total_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ostringstream figures;
  figures << surf.at("triangles") << " triangles; voxel " << h << ", box off OpenVDB's by "
          << box_error << " m, outside the block by " << outside_block << " m; surface box ["
          << box.x0 << ", " << box.x1 << ") x [" << box.y0 << ", " << box.y1 << ") of "
          << box.area() << " pixels: " << changed_in << " changed by > 0.1 against hidden ("
          << changed_all - changed_in << " outside), mean |surface - hidden| " << shown_in.mean
          << "; against the fog " << fog_changed_in << " changed, mean |surface - fog| "
          << vs_fog.mean << "; mean brightness surface " << surface_in.mean << ", fog "
          << fog_in.mean << ", hidden " << bare_in.mean << "; Blender " << surface.seconds
          << " s + " << bare.seconds << " s + " << fog.seconds << " s, total " << total_seconds
          << " s";
  INFO(figures.str());
  // Measured: 1.5e-8 m off OpenVDB's box (0.025 m, half a voxel, without the loader's
  // shift), 0.011 m outside the block.
  CHECK(box_error <= 0.1 * h);
  CHECK(outside_block <= 0.5 * h);
  // Opaque: the block covers 63% of its box's pixels, changed by 0.116 on average against
  // the render without it (a surface of alpha 0.15: 38%, 0.043), and nothing outside it.
  CHECK(changed_in >= box.area() / 2);
  CHECK(shown_in.mean > 0.07);
  CHECK(changed_all - changed_in <= 5);
  // Not the fog: 85% of the box's pixels differ from the fog render's by more than 0.1, by
  // 0.185 on average, and the lit surface is brighter (0.589) than the fog (0.406).
  CHECK(fog_changed_in >= box.area() / 4);
  CHECK(vs_fog.mean > 0.05);
  CHECK(surface_in.mean > fog_in.mean + 0.05);
  WARN("blender loader --bulk surface: " << figures.str());
}

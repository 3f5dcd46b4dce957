// Quantitative image checks of both render paths on scenes with known answers.
#include <catch2/catch.hpp>
#include <cmath>

#include "render/raster_renderer.h"
#include "render/ray_tracer.h"
#include "sim/core/parallel.h"
#include "tests/render/render_test_scenes.h"

using namespace shellmpm;
using namespace shellmpm_test;

namespace {

/// The analytic silhouette area [pixels] of a sphere of radius r at distance d on the
/// optical axis: a disc of radius f r / sqrt(d^2 - r^2), f the focal length in pixels.
double sphere_silhouette_area(double r, double d, const Camera& cam) {
  const double f = 0.5 * cam.height / cam.tan_half_fov();
  const double rho = f * r / std::sqrt(d * d - r * r);
  return M_PI * rho * rho;
}

PreviewScene mixed_scene() {
  PreviewScene s = sphere_scene(Vec3d(0.3, 0.1, 0.0), 0.35);
  RenderMesh box = tessellate_box(Vec3d(-0.9, -0.4, -0.3), Vec3d(-0.3, 0.2, 0.2));
  box.kind = SurfaceKind::Collider;
  box.front = box.back = Vec3f(0.5f, 0.5f, 0.55f);
  s.meshes.push_back(box);
  // A sheet (two-sided shell) tilted towards the camera.
  RenderMesh sheet = tessellate_square(Vec3d(0.0, 0.6, -0.5), Vec3d(0.2, 0.6, 1.0), 0.5, 20);
  sheet.kind = SurfaceKind::Shell;
  sheet.front = Vec3f(0.8f, 0.3f, 0.2f);
  sheet.back = Vec3f(0.2f, 0.4f, 0.8f);
  s.meshes.push_back(sheet);
  // A blob of particles.
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j)
      for (int k = 0; k < 6; ++k)
        s.particles.positions.emplace_back(-0.2f + 0.03f * i, -0.6f + 0.03f * k, 0.3f + 0.03f * j);
  s.particles.radius = 0.02f;
  s.particles.color = Vec3f(0.8f, 0.7f, 0.4f);
  s.bounds_lo = Vec3f(-1, -1, -1);
  s.bounds_hi = Vec3f(1, 1, 1);
  return s;
}

}  // namespace

TEST_CASE("a sphere's silhouette area is within 1% of the analytic value in both paths",
          "[render]") {
  const double r = 0.5, d = 3.0;
  const PreviewScene s = sphere_scene(Vec3d(0, 0, 0), r);
  const Camera cam = camera_at(Vec3d(0, 0, d), Vec3d(0, 0, 0), 320, 240);
  const double exact = sphere_silhouette_area(r, d, cam);
  REQUIRE(exact > 5000.0);  // a resolved disc, not a few pixels
  RasterRenderer raster(2);
  RayTracer rt(2);
  const double a_raster = coverage_area(raster.render(s, cam));
  const double a_rt = coverage_area(rt.render(s, cam));
  CAPTURE(exact, a_raster, a_rt);
  CHECK(std::abs(a_raster / exact - 1.0) < 0.01);
  CHECK(std::abs(a_rt / exact - 1.0) < 0.01);
  // And off-axis, nearer: still an exact projection (an ellipse now; compare the paths).
  const Camera near = camera_at(Vec3d(1.2, 0.4, 1.6), Vec3d(-0.3, 0.1, 0), 320, 240, 55.0);
  const double b_raster = coverage_area(raster.render(s, near));
  const double b_rt = coverage_area(rt.render(s, near));
  CAPTURE(b_raster, b_rt);
  CHECK(std::abs(b_raster / b_rt - 1.0) < 0.01);
}

TEST_CASE("the raster and ray traced silhouettes of one scene agree (IoU >= 0.98)", "[render]") {
  const PreviewScene s = mixed_scene();
  RasterRenderer raster(2);
  RayTracer rt(2);
  for (const Camera& cam : {camera_at(Vec3d(0.5, 0.8, 3.0), Vec3d(0, 0, 0), 320, 240),
                            camera_at(Vec3d(-2.0, 1.5, 1.0), Vec3d(0, 0, 0), 240, 240, 50.0)}) {
    const Image a = raster.render(s, cam), b = rt.render(s, cam);
    const double iou = mask_iou(a, b);
    CAPTURE(iou, coverage_area(a), coverage_area(b));
    CHECK(coverage_area(a) > 0.05 * cam.width * cam.height);
    CHECK(iou >= 0.98);
  }
}

TEST_CASE("the key light's shadow falls where the geometry puts it, in both paths", "[render]") {
  // A sphere above a level ground, the key light along (1, 1, 0): the shadow's center is
  // the sphere's center moved along -(1, 1, 0) down to the ground, at (-0.6, 0, 0).
  PreviewScene s = sphere_scene(Vec3d(0, 0.6, 0), 0.25);
  set_lights(s, Vec3f(1, 1, 0));
  RenderMesh g = tessellate_square(Vec3d(0, 0, 0), Vec3d(0, 1, 0), 3.0, 16);
  g.kind = SurfaceKind::Ground;
  g.front = g.back = Vec3f(0.5f, 0.5f, 0.5f);
  s.meshes.push_back(g);
  s.ground.center = Vec3f(0, 0, 0);
  s.ground.radius = 3.0f;
  s.ground.tile = 100.0f;  // one checker square: no pattern in the comparison
  s.bounds_lo = Vec3f(-0.3f, 0.0f, -0.3f);
  s.bounds_hi = Vec3f(0.3f, 0.9f, 0.3f);
  const Camera cam = camera_at(Vec3d(0, 2.5, 3.0), Vec3d(-0.3, 0, 0), 320, 240);
  const Vec3d shadow(-0.6, 0, 0), beside(-0.6, 0, 0.8), mirrored(0.6, 0, 0);
  // None of the three ground points is hidden by the sphere in this view.
  const Eigen::Vector3d sc = cam.project(Vec3d(0, 0.6, 0));
  for (const Vec3d& p : {shadow, beside, mirrored})
    REQUIRE((cam.project(p) - sc).head<2>().norm() > 60.0);
  RasterRenderer raster(2);
  RayTracer rt(2);
  for (Renderer* r : std::vector<Renderer*>{&raster, &rt}) {
    const Image im = r->render(s, cam);
    auto lum = [&](const Vec3d& p) {
      const Eigen::Vector3d q = cam.project(p);
      return luminance(im, static_cast<int>(q.x()), static_cast<int>(q.y()));
    };
    CAPTURE(r->name(), lum(shadow), lum(beside), lum(mirrored));
    CHECK(lum(shadow) < 0.75 * lum(beside));
    CHECK(lum(shadow) < 0.75 * lum(mirrored));
    CHECK(std::abs(lum(beside) - lum(mirrored)) < 0.1 * lum(beside));  // both lit
  }
}

TEST_CASE("a shell shows its front colour from the front and its back colour from behind",
          "[render]") {
  PreviewScene s;
  RenderMesh sheet = tessellate_square(Vec3d(0, 0, 0), Vec3d(0, 0, 1), 0.5, 4);
  sheet.kind = SurfaceKind::Shell;
  sheet.front = Vec3f(0.9f, 0.1f, 0.1f);
  sheet.back = Vec3f(0.1f, 0.1f, 0.9f);
  s.meshes.push_back(sheet);
  set_lights(s, Vec3f(0, 0.2f, 1));
  s.lights.key_dir = Vec3f(0, 0, 1);
  s.ao_samples = 0;
  RasterRenderer raster(2);
  RayTracer rt(2);
  for (Renderer* r : std::vector<Renderer*>{&raster, &rt}) {
    for (double side : {1.0, -1.0}) {
      const Image im = r->render(s, camera_at(Vec3d(0, 0, 2 * side), Vec3d(0, 0, 0), 64, 48));
      const std::uint8_t* p = im.pixel(32, 24);
      CAPTURE(r->name(), side, int(p[0]), int(p[2]));
      if (side > 0)
        CHECK(p[0] > p[2] + 50);
      else
        CHECK(p[2] > p[0] + 50);
    }
  }
}

TEST_CASE("renders are deterministic: same scene, same pixels, whatever the thread count",
          "[render]") {
  PreviewScene s = mixed_scene();
  s.ao_samples = 2;
  const Camera cam = camera_at(Vec3d(0.5, 0.8, 3.0), Vec3d(0, 0, 0), 160, 120);
  RayTracer rt(2);
  Image a, b;
  {
    ThreadLimit one(1);
    a = rt.render(s, cam);
  }
  {
    ThreadLimit two(2);
    b = rt.render(s, cam);
  }
  CHECK(a.rgba == b.rgba);
  RasterRenderer raster(2);
  const Image c = raster.render(s, cam), d = raster.render(s, cam);
  CHECK(c.rgba == d.rgba);
}

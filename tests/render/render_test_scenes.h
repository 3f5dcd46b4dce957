// Small hand-built preview scenes with known answers, shared by the render tests.
#pragma once
#include <cmath>

#include "render/camera.h"
#include "render/image.h"
#include "render/preview_scene.h"
#include "render/tessellate.h"

namespace shellmpm_test {

using namespace shellmpm;

/// Lights with no fill and no ambient surprises: key from `key_dir`.
inline void set_lights(PreviewScene& s, const Vec3f& key_dir) {
  s.lights.key_dir = key_dir.normalized();
  s.lights.fill_dir = Vec3f(-0.6f, 0.3f, 0.7f).normalized();
  s.lights.key = 0.8f;
  s.lights.fill = 0.25f;
  s.lights.ambient = 0.3f;
}

/// One sphere collider, no ground.
inline PreviewScene sphere_scene(const Vec3d& c, double r) {
  PreviewScene s;
  RenderMesh m = tessellate_sphere(c, r, 128);
  m.kind = SurfaceKind::Collider;
  m.front = m.back = Vec3f(0.6f, 0.6f, 0.6f);
  s.meshes.push_back(m);
  s.bounds_lo = (c.array() - r).matrix().cast<float>();
  s.bounds_hi = (c.array() + r).matrix().cast<float>();
  s.ground.center = c.cast<float>();
  s.ground.radius = 10.0f;
  s.ao_distance = static_cast<float>(0.3 * r);
  s.samples = 4;
  s.ao_samples = 0;
  set_lights(s, Vec3f(0.3f, 1.0f, 0.4f));
  return s;
}

inline Camera camera_at(const Vec3d& eye, const Vec3d& target, int w, int h, double fov = 40.0) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.width = w;
  c.height = h;
  c.fov_deg = fov;
  return c;
}

/// Coverage summed over the image [pixels].
inline double coverage_area(const Image& im) {
  double a = 0;
  for (std::size_t i = 3; i < im.rgba.size(); i += 4) a += im.rgba[i] / 255.0;
  return a;
}

/// Luminance of pixel (x, y), 0..255 (gamma-encoded values, Rec. 709 weights).
inline double luminance(const Image& im, int x, int y) {
  const std::uint8_t* p = im.pixel(x, y);
  return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

/// Intersection over union of the masks alpha >= 128.
inline double mask_iou(const Image& a, const Image& b) {
  long inter = 0, uni = 0;
  for (std::size_t i = 3; i < a.rgba.size(); i += 4) {
    const bool x = a.rgba[i] >= 128, y = b.rgba[i] >= 128;
    inter += x && y;
    uni += x || y;
  }
  return uni ? static_cast<double>(inter) / uni : 1.0;
}

}  // namespace shellmpm_test

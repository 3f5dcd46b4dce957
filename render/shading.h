// The shading rules both render paths follow (the raster path has the same formulas in
// GLSL, in render/raster_renderer.cpp; keep the two in step). Colours are linear RGB;
// images store them gamma-encoded (encode_channel).
//
//   colour = albedo * (ambient * ao * (0.55 + 0.45 n.y) + key * shadow * max(0, n.key)
//                      + fill * max(0, n.fill))
//
// n faces the viewer. Shells take their front or back albedo by the side seen; the ground
// is checkered and fades into the background towards its rim.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "render/preview_scene.h"

namespace shellmpm {

/// Lit colour of a surface point (see the file comment). `shadow` is the key light's
/// visibility in [0, 1], `ao` the sky's.
inline Vec3f shade_surface(const RenderLights& l, const Vec3f& albedo, const Vec3f& n, float shadow,
                           float ao) {
  const float sky = l.ambient * ao * (0.55f + 0.45f * n.y());
  const float key = l.key * shadow * std::max(0.0f, n.dot(l.key_dir));
  const float fill = l.fill * std::max(0.0f, n.dot(l.fill_dir));
  return albedo * (sky + key + fill);
}

/// The ground's albedo at world point p: a checker of `tile` squares in the plane's
/// axes (world x and z for a level ground), the odd squares 18% darker.
inline Vec3f ground_albedo(const RenderGround& g, const Vec3f& albedo, const Vec3f& p) {
  const float u = std::floor(p.x() / g.tile), v = std::floor(p.z() / g.tile);
  const bool odd = static_cast<long long>(u + v) % 2 != 0;
  return odd ? Vec3f(albedo * 0.82f) : albedo;
}

/// How much of the background shows through the ground at p: 0 near the center, 1 at
/// the rim (smoothstep from 55% to 100% of the radius).
inline float ground_fade(const RenderGround& g, const Vec3f& p) {
  const float d = (p - g.center).norm() / g.radius;
  const float x = std::clamp((d - 0.55f) / 0.45f, 0.0f, 1.0f);
  return x * x * (3.0f - 2.0f * x);
}

/// Background at image row position y01 (0 at the bottom edge, 1 at the top).
inline Vec3f background(const PreviewScene& s, float y01) {
  return s.bg_bottom + (s.bg_top - s.bg_bottom) * y01;
}

/// Linear [0, 1] -> gamma-encoded 8-bit (gamma 2.2, rounded).
inline std::uint8_t encode_channel(float linear) {
  const float c = std::pow(std::clamp(linear, 0.0f, 1.0f), 1.0f / 2.2f);
  return static_cast<std::uint8_t>(std::lround(c * 255.0f));
}

}  // namespace shellmpm

// Hidden-particle culling drops only particles buried under full layers of neighbours.
#include <catch2/catch.hpp>

#include "render/particle_culling.h"

using namespace shellmpm;

namespace {
RenderParticles block(int n, float spacing) {
  RenderParticles p;
  p.radius = 0.5f * spacing;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) p.positions.emplace_back(spacing * i, spacing * j, spacing * k);
  return p;
}
}  // namespace

TEST_CASE("particle culling keeps the outer layers of a packed block and drops its core",
          "[render]") {
  const float s = 0.01f;
  RenderParticles p = block(30, s);
  const std::size_t removed = cull_hidden_particles(p);
  CHECK(removed > 0);
  CHECK(removed + p.positions.size() == 27000u);
  // Every particle within two spacings of the surface is kept (it can be seen).
  std::size_t outer = 0;
  for (const Vec3f& x : block(30, s).positions) {
    const float d = std::min({x.x(), x.y(), x.z(), 29 * s - x.x(), 29 * s - x.y(), 29 * s - x.z()});
    if (d < 2.5f * s) {
      ++outer;
      CHECK(std::find(p.positions.begin(), p.positions.end(), x) != p.positions.end());
    }
  }
  CHECK(p.positions.size() >= outer);
  // Survivors keep their order.
  CHECK(std::is_sorted(p.positions.begin(), p.positions.end(), [](const Vec3f& a, const Vec3f& b) {
    return std::make_tuple(a.z(), a.y(), a.x()) < std::make_tuple(b.z(), b.y(), b.x());
  }));
}

TEST_CASE("particle culling drops nothing from a thin sheet or a sparse spray", "[render]") {
  RenderParticles sheet;
  sheet.radius = 0.005f;
  for (int i = 0; i < 100; ++i)
    for (int j = 0; j < 100; ++j)
      sheet.positions.emplace_back(0.01f * i, 0.01f * (j % 2), 0.01f * (j / 2));
  CHECK(cull_hidden_particles(sheet) == 0);
  RenderParticles spray;
  spray.radius = 0.001f;
  for (int i = 0; i < 1000; ++i)
    spray.positions.emplace_back(0.01f * i, 0.013f * (i % 7), 0.017f * (i % 11));
  CHECK(cull_hidden_particles(spray) == 0);
}

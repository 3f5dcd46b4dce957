#include <catch2/catch.hpp>

#include "sim/solver/source_sampler.h"

using namespace shellmpm;

TEST_CASE("fill sampling: particle count and volume match the shape", "[sampling]") {
  SourceDesc s;
  s.shape.kind = ShapeDesc::Kind::Sphere;
  s.shape.center = Vec3d(0.3, 0.2, 0.1);
  s.shape.radius = 0.25;
  s.particles_per_cell = 8;
  SourceSampler sm(s, 0.02, 24);
  REQUIRE(sm.spacing() == Approx(0.01));
  std::size_t n = 0;
  Vec3d c = Vec3d::Zero();
  sm.fill([&](const Vec3d& p) {
    REQUIRE(shape_phi(s.shape, p) < 0);
    c += p;
    ++n;
  });
  const double vol = 4.0 / 3.0 * M_PI * std::pow(0.25, 3);
  REQUIRE(n * sm.particle_volume() == Approx(vol).epsilon(0.01));
  REQUIRE((c / double(n) - s.shape.center).norm() < 1e-3);
  // Deterministic: same seed, same points; another seed, other points.
  std::vector<Vec3d> a, b, d;
  sm.fill([&](const Vec3d& p) { a.push_back(p); });
  sm.fill([&](const Vec3d& p) { b.push_back(p); });
  s.seed = 2;
  SourceSampler other(s, 0.02, 24);
  other.fill([&](const Vec3d& p) { d.push_back(p); });
  REQUIRE(a == b);
  REQUIRE(a != d);
}

TEST_CASE("emission: flow rate = |v| * cross-section, independent of the step", "[sampling]") {
  SourceDesc s;
  s.shape.kind = ShapeDesc::Kind::Box;
  s.shape.min = Vec3d(0, 0, 0);
  s.shape.max = Vec3d(0.2, 0.1, 0.2);
  s.velocity = Vec3d(0, -1.5, 0);
  s.emit = true;
  s.emit_start = 1;
  s.emit_end = 12;  // 0 .. 0.5 s at 24 fps
  s.particles_per_cell = 8;
  SourceSampler sm(s, 0.02, 24);
  auto count = [&](double dt) {
    std::size_t n = 0;
    for (double t = 0; t < 0.5 - 1e-12; t += dt)
      sm.emit(t, dt, [&](const Vec3d& p) {
        REQUIRE(shape_phi(s.shape, p) >= -1e-9);  // released outside the nozzle
        ++n;
      });
    return n;
  };
  const std::size_t coarse = count(1.0 / 240), fine = count(1.0 / 2400);
  const double expected = 1.5 * 0.5 * 0.2 * 0.2 / sm.particle_volume();
  REQUIRE(coarse == Approx(expected).epsilon(0.03));
  REQUIRE(std::abs(double(coarse) - double(fine)) <= 0.01 * expected);
  // Nothing outside the window.
  std::size_t late = 0;
  sm.emit(0.6, 0.01, [&](const Vec3d&) { ++late; });
  REQUIRE(late == 0);
}

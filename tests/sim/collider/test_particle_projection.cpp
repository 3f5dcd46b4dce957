// Particle-level collider projection (sim/collider/particle_projection.h): points inside
// a collider come out onto its surface, points a thin fast collider passed over go back
// to the side they came from, and a point in the corner of a blade and the ground ends
// outside both.
#include <catch2/catch.hpp>

#include "sim/collider/particle_projection.h"

using namespace shellmpm;

namespace {

ColliderDesc blade(double x0, double x1, double t1) {
  ColliderDesc c;
  c.name = "blade";
  c.shape.kind = ShapeDesc::Kind::Box;
  c.shape.min = Vec3d(-0.005, 0.0, -0.2);  // 1 cm thick, half a cell at dx = 0.02
  c.shape.max = Vec3d(0.005, 0.3, 0.2);
  c.boundary = BoundaryKind::Separate;
  Keyframe a, b;
  a.time = 0;
  a.translate = Vec3d(x0, 0, 0);
  b.time = t1;
  b.translate = Vec3d(x1, 0, 0);
  c.keyframes = {a, b};
  return c;
}

ColliderDesc ground() {
  ColliderDesc c;
  c.name = "ground";
  c.shape.kind = ShapeDesc::Kind::Plane;
  c.shape.point = Vec3d::Zero();
  c.shape.normal = Vec3d(0, 1, 0);
  c.boundary = BoundaryKind::Separate;
  return c;
}

}  // namespace

TEST_CASE("a point inside a moving blade is put on its surface and moves with it", "[collider]") {
  std::vector<Collider> cs{Collider(blade(0.0, 1.0, 0.1))};  // 10 m/s along +x
  const double dt = 1e-3, dx = 0.02;
  cs[0].begin_step(0.05, dt);  // blade at x = 0.51 at the end of the step
  std::vector<Vec3> x{Vec3(0.512f, 0.1f, 0.0f)}, v{Vec3::Zero()};
  const ProjectionStats st = project_out_of_colliders(cs, dx, dt, x, v, nullptr, true);
  CHECK(st.inside == 1);
  CHECK(cs[0].phi(x[0].cast<double>()) > -1e-6);
  CHECK(x[0].x() == Approx(0.515).margin(1e-5));
  CHECK(x[0].x() >= 0.515f);                      // the blade's +x face
  CHECK(v[0].x() == Approx(10.0).epsilon(1e-3));  // no normal velocity into the blade
}

TEST_CASE("a thin blade that passes over a point in one step sends it back to the front",
          "[collider]") {
  // 100 m/s: the blade moves 0.1 m = 5 dx in the step, far more than its thickness.
  std::vector<Collider> cs{Collider(blade(-0.05, 0.95, 0.01))};
  const double dt = 1e-3, dx = 0.02;
  cs[0].begin_step(0.0, dt);  // from x = -0.05 to x = 0.05
  std::vector<Vec3> x{Vec3(0.0f, 0.1f, 0.0f)}, v{Vec3::Zero()};
  REQUIRE(cs[0].phi(x[0].cast<double>()) > 0);  // outside at both ends of the step
  const ProjectionStats st = project_out_of_colliders(cs, dx, dt, x, v, nullptr, true);
  CHECK(st.swept == 1);
  CHECK(x[0].x() > 0.05f);  // ahead of the blade, as if pushed
  CHECK(v[0].x() == Approx(100.0).epsilon(1e-3));
  // A point the blade does not reach is left alone.
  std::vector<Vec3> y{Vec3(0.2f, 0.1f, 0.0f)}, w{Vec3::Zero()};
  const ProjectionStats none = project_out_of_colliders(cs, dx, dt, y, w, nullptr, true);
  CHECK(none.inside + none.swept == 0);
  CHECK(y[0].x() == 0.2f);
}

TEST_CASE("a point in the corner of a blade and the ground ends outside both", "[collider]") {
  ColliderDesc b = blade(0.0, 1.0, 0.1);
  b.shape.min.y() = -0.1;  // the blade reaches into the ground
  std::vector<Collider> cs{Collider(b), Collider(ground())};
  const double dt = 1e-3, dx = 0.02;
  for (Collider& c : cs) c.begin_step(0.05, dt);
  // Inside the blade near its front face and below the ground.
  std::vector<Vec3> x{Vec3(0.513f, -0.004f, 0.0f)}, v{Vec3(0.0f, -1.0f, 0.0f)};
  project_out_of_colliders(cs, dx, dt, x, v, nullptr, true);
  for (const Collider& c : cs) CHECK(c.phi(x[0].cast<double>()) > -1e-6);
  CHECK(v[0].y() >= 0.0f);
}

TEST_CASE("pinned points are not projected", "[collider]") {
  std::vector<Collider> cs{Collider(ground())};
  cs[0].begin_step(0.0, 1e-3);
  std::vector<Vec3> x{Vec3(0.0f, -0.01f, 0.0f)}, v{Vec3::Zero()};
  std::vector<std::uint8_t> held{7};
  project_out_of_colliders(cs, 0.02, 1e-3, x, v, &held, true);
  CHECK(x[0].y() == -0.01f);
}

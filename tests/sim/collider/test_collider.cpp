#include <catch2/catch.hpp>

#include "sim/collider/collider.h"

using namespace shellmpm;

namespace {
ColliderDesc plane_collider(BoundaryKind b, double mu) {
  ColliderDesc c;
  c.shape.kind = ShapeDesc::Kind::Plane;
  c.shape.point = Vec3d::Zero();
  c.shape.normal = Vec3d(0, 1, 0);
  c.boundary = b;
  c.friction = mu;
  return c;
}
}  // namespace

TEST_CASE("shape signed distances", "[collider]") {
  ShapeDesc box;
  box.kind = ShapeDesc::Kind::Box;
  box.min = Vec3d(-1, -1, -1);
  box.max = Vec3d(1, 2, 1);
  REQUIRE(shape_phi(box, Vec3d(0, 0, 0)) == Approx(-1));
  REQUIRE(shape_phi(box, Vec3d(3, 0, 0)) == Approx(2));
  REQUIRE(shape_phi(box, Vec3d(2, 3, 0)) == Approx(std::sqrt(2.0)));
  ShapeDesc cyl;
  cyl.kind = ShapeDesc::Kind::Cylinder;
  cyl.center = Vec3d(0, 0, 0);
  cyl.axis = Vec3d(0, 0, 1);
  cyl.radius = 0.5;
  cyl.height = 2;
  REQUIRE(shape_phi(cyl, Vec3d(1, 0, 0)) == Approx(0.5));
  REQUIRE(shape_phi(cyl, Vec3d(0, 0, 1.5)) == Approx(0.5));
  REQUIRE(shape_phi(cyl, Vec3d(0.1, 0, 0)) == Approx(-0.4));
  REQUIRE((shape_normal(cyl, Vec3d(1, 0, 0)) - Vec3d(1, 0, 0)).norm() < 1e-6);
  ShapeDesc sph;
  sph.kind = ShapeDesc::Kind::Sphere;
  sph.center = Vec3d(1, 1, 1);
  sph.radius = 1;
  REQUIRE(shape_phi(sph, Vec3d(1, 3, 1)) == Approx(1));
}

TEST_CASE("collider boundary conditions", "[collider]") {
  const Vec3d inside(0, -0.01, 0), outside(0, 0.5, 0);
  SECTION("outside: untouched") {
    Collider c(plane_collider(BoundaryKind::Sticky, 0));
    Vec3 v(1, -1, 0);
    REQUIRE_FALSE(c.apply(outside, v));
    REQUIRE(v == Vec3(1, -1, 0));
  }
  SECTION("sticky: the collider's velocity") {
    Collider c(plane_collider(BoundaryKind::Sticky, 0));
    Vec3 v(1, -1, 0);
    REQUIRE(c.apply(inside, v));
    REQUIRE(v.norm() == 0);
  }
  SECTION("slip: normal part removed even when separating") {
    Collider c(plane_collider(BoundaryKind::Slip, 0));
    Vec3 v(1, 2, 0);
    c.apply(inside, v);
    REQUIRE(v.x() == Approx(1));
    REQUIRE(v.y() == Approx(0).margin(1e-7));
  }
  SECTION("separate: separating velocity kept, approaching removed") {
    Collider c(plane_collider(BoundaryKind::Separate, 0));
    Vec3 v(1, 2, 0);
    c.apply(inside, v);
    REQUIRE(v.y() == Approx(2));
    v = Vec3(1, -2, 0);
    c.apply(inside, v);
    REQUIRE(v.y() == Approx(0).margin(1e-7));
    REQUIRE(v.x() == Approx(1));
  }
  SECTION("Coulomb friction reduces tangential speed by mu |v_n|, or stops it") {
    Collider c(plane_collider(BoundaryKind::Separate, 0.25));
    Vec3 v(1, -2, 0);
    c.apply(inside, v);
    REQUIRE(v.x() == Approx(0.5));
    v = Vec3(0.3, -2, 0);
    c.apply(inside, v);
    REQUIRE(v.x() == Approx(0).margin(1e-7));
  }
}

TEST_CASE("keyframed colliders move and carry their velocity", "[collider]") {
  std::vector<Keyframe> keys(2);
  keys[0].time = 0;
  keys[1].time = 2;
  keys[1].translate = Vec3d(2, 0, 0);
  keys[1].rotate_deg = Vec3d(0, 90, 0);
  const RigidPose mid = keyframe_pose(keys, 1.0);
  REQUIRE((mid.t - Vec3d(1, 0, 0)).norm() < 1e-12);
  // Half of a 90 degree turn about y.
  const Vec3d ex = mid.R * Vec3d(1, 0, 0);
  REQUIRE(ex.x() == Approx(std::cos(M_PI / 4)));
  REQUIRE(ex.z() == Approx(-std::sin(M_PI / 4)));
  // Held before the first and after the last key.
  REQUIRE((keyframe_pose(keys, 5).t - Vec3d(2, 0, 0)).norm() < 1e-12);
  // A spinning box: velocity = translation rate + omega x r.
  ColliderDesc d;
  d.shape.kind = ShapeDesc::Kind::Box;
  d.shape.min = Vec3d(-1, -1, -1);
  d.shape.max = Vec3d(1, 1, 1);
  d.keyframes = keys;
  d.boundary = BoundaryKind::Sticky;
  Collider c(d);
  const double dt = 1e-4;
  c.begin_step(1.0, dt);
  const Vec3d x = mid.t + Vec3d(0.5, 0.2, 0.1);
  const Vec3d omega(0, M_PI / 4, 0);  // 90 degrees over 2 s
  const Vec3d expect = Vec3d(1, 0, 0) + omega.cross(x - mid.t);
  REQUIRE((c.velocity(x) - expect).norm() < 1e-3);
  // The fastest point is a corner of the box: |translation rate + omega x r| there.
  double vmax = 0;
  for (int k = 0; k < 8; ++k) {
    const Vec3d corner((k & 4) ? 1 : -1, (k & 2) ? 1 : -1, (k & 1) ? 1 : -1);
    vmax = std::max(vmax, (Vec3d(1, 0, 0) + omega.cross(mid.R * corner)).norm());
  }
  REQUIRE(c.max_speed(1.0) == Approx(vmax).epsilon(1e-3));
  REQUIRE(Collider(plane_collider(BoundaryKind::Slip, 0)).max_speed(1.0) == 0);
  Vec3 v(5, 5, 5);
  REQUIRE(c.apply(x, v));
  REQUIRE((v.cast<double>() - expect).norm() < 1e-3);
}

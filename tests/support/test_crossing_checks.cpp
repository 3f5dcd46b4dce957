// The stress suite's independent judges (tests/support/crossing_checks.h) find what they
// should and nothing else: crossing meshes, points through a shell, collider depth.
#include <catch2/catch.hpp>

#include "tests/support/crossing_checks.h"

using namespace shellmpm_test;

namespace {

/// A flat n x n sheet of side `size` in the XZ plane at height y, normal +Y, centered at
/// (cx, y, cz).
TriMesh sheet(int n, double size, double y, double cx = 0, double cz = 0) {
  TriMesh m;
  const double h = size / n;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.x.emplace_back(cx - size / 2 + i * h, y, cz - size / 2 + j * h);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = i + (n + 1) * j, b = a + 1, c = a + n + 2, d = a + n + 1;
      m.tri.emplace_back(a, c, b);  // (c - a) x (b - a) points +Y
      m.tri.emplace_back(a, d, c);
    }
  return m;
}

/// Applies x -> R x + t to every vertex.
TriMesh moved(TriMesh m, const Eigen::Matrix3d& R, const V3& t) {
  for (V3& x : m.x) x = R * x + t;
  return m;
}

/// Two meshes as one (the second's indices shifted).
TriMesh joined(const TriMesh& a, const TriMesh& b) {
  TriMesh m = a;
  const int off = static_cast<int>(a.x.size());
  m.x.insert(m.x.end(), b.x.begin(), b.x.end());
  for (const Eigen::Vector3i& t : b.tri) m.tri.emplace_back(t + Eigen::Vector3i::Constant(off));
  return m;
}

const Eigen::Matrix3d kRotX90 = Eigen::AngleAxisd(M_PI / 2, V3::UnitX()).toRotationMatrix();

}  // namespace

TEST_CASE("crossing checks: segment against triangle", "[stress_checks]") {
  const V3 a(0, 0, 0), b(1, 0, 0), c(0, 0, 1);
  CHECK(segment_triangle(V3(0.2, 1, 0.2), V3(0.2, -1, 0.2), a, b, c) == Crossing::Clear);
  CHECK(segment_triangle(V3(0.2, 1, 0.2), V3(0.2, 0.1, 0.2), a, b, c) == Crossing::None);
  CHECK(segment_triangle(V3(0.8, 1, 0.8), V3(0.8, -1, 0.8), a, b, c) == Crossing::None);
  // An endpoint on the plane, and a crossing on an edge, are borderline.
  CHECK(segment_triangle(V3(0.2, 0, 0.2), V3(0.2, -1, 0.2), a, b, c) == Crossing::Borderline);
  CHECK(segment_triangle(V3(0.5, 1, 0.5), V3(0.5, -1, 0.5), a, b, c) == Crossing::Borderline);
  // Orientation of the triangle and direction of the segment do not matter.
  CHECK(segment_triangle(V3(0.2, -1, 0.2), V3(0.2, 1, 0.2), a, c, b) == Crossing::Clear);
  // In the plane: not a crossing.
  CHECK(segment_triangle(V3(-1, 0, 0.2), V3(2, 0, 0.2), a, b, c) == Crossing::None);
}

TEST_CASE("crossing checks: meshes that pass through each other are found", "[stress_checks]") {
  const TriMesh flat = sheet(8, 1.0, 0.0);
  // A vertical sheet (XY plane) through the middle of the flat one (no vertex of one on
  // the other's plane).
  const TriMesh through = moved(sheet(8, 0.6, 0.0), kRotX90, V3(0.05, 0.013, 0.013));
  const EdgeCrossings hit = pair_crossings(flat, through);
  CHECK(hit.clear > 0);
  CHECK(std::abs(hit.where.y()) < 0.2);
  // The same vertical sheet lifted clear of the flat one: nothing.
  const TriMesh above = moved(sheet(8, 0.6, 0.0), kRotX90, V3(0.05, 0.35, 0.013));
  CHECK(pair_crossings(flat, above).any() == 0);
  // Stacked parallel sheets 1 mm apart: nothing.
  CHECK(pair_crossings(flat, sheet(8, 1.0, 0.001, 0.03, 0.02)).any() == 0);
  // Self: one mesh holding both crossing parts crosses itself; a flat sheet does not.
  CHECK(self_crossings(joined(flat, through)).clear > 0);
  CHECK(self_crossings(joined(flat, above)).any() == 0);
  CHECK(self_crossings(flat).any() == 0);
  // A sheet folded over onto itself at x = 0, the upper leaf 0 to 2 mm above the lower
  // one, does not cross itself; a leaf folded at x = 0.25 that comes back down through
  // the lower leaf does.
  TriMesh fold = sheet(8, 1.0, 0.0);
  for (V3& x : fold.x)
    if (x.x() > 0) x = V3(-x.x(), 0.004 * x.x(), x.z());
  CHECK(self_crossings(fold).any() == 0);
  TriMesh pierce = sheet(8, 1.0, 0.0);
  for (V3& x : pierce.x)
    if (x.x() > 0.25) {
      const double s = x.x() - 0.25;
      x = V3(0.25 - s, 0.2 * s - 1.2 * s * s, x.z());
    }
  CHECK(self_crossings(pierce).clear > 0);
}

TEST_CASE("crossing checks: a point that jumps through a shell is counted", "[stress_checks]") {
  const double dx = 0.02;
  const TriMesh rest = sheet(10, 1.0, 0.0);
  const ShellSurface surf(rest, 2 * dx, 2 * dx, 1e-3 * dx);
  const std::vector<int> ids = {7};
  const auto flips = [&](const ShellSurface& s0, const ShellSurface& s1, const V3& p0,
                         const V3& p1) {
    return count_crossings(s0, s1, std::vector<V3>{p0}, ids, std::vector<V3>{p1}, ids, 4 * dx);
  };
  // Straight through the middle, between two frames.
  CHECK(flips(surf, surf, V3(0.013, 0.01, 0.021), V3(0.017, -0.015, 0.02)) == 1);
  // Through at a vertex and along an edge (pseudo-normals give the side there too).
  CHECK(flips(surf, surf, V3(0.1, 0.01, 0.1), V3(0.1, -0.01, 0.1)) == 1);
  CHECK(flips(surf, surf, V3(0.15, 0.01, 0.1), V3(0.15, -0.01, 0.1)) == 1);
  // Staying on one side, moving along: nothing.
  CHECK(flips(surf, surf, V3(0.0, 0.01, 0.0), V3(0.03, 0.02, 0.01)) == 0);
  // Around the edge: close to the boundary (within 2 dx, rest distance) in both frames.
  CHECK(flips(surf, surf, V3(0.49, 0.01, 0.0), V3(0.495, -0.01, 0.0)) == 0);
  CHECK(flips(surf, surf, V3(0.53, 0.01, 0.0), V3(0.47, -0.01, 0.0)) == 0);
  // Out of the band in one of the frames: not judged (the point may have gone round).
  CHECK(flips(surf, surf, V3(0.0, 0.05, 0.0), V3(0.0, -0.01, 0.0)) == 0);
  // The shell passing through a point that stays put is a crossing too.
  ShellSurface up(rest, 2 * dx, 2 * dx, 1e-3 * dx);
  up.set_frame(moved(rest, Eigen::Matrix3d::Identity(), V3(0, 0.02, 0)));
  CHECK(flips(surf, up, V3(0.0, 0.01, 0.0), V3(0.0, 0.01, 0.0)) == 1);
  // Particles are matched by id: a different id is a different particle.
  CHECK(count_crossings(surf, surf, std::vector<V3>{V3(0, 0.01, 0)}, std::vector<int>{1},
                        std::vector<V3>{V3(0, -0.01, 0)}, std::vector<int>{2}, 4 * dx) == 0);
}

TEST_CASE("crossing checks: a point near another layer of the same shell is not counted",
          "[stress_checks]") {
  const double dx = 0.02;
  // Two layers of one shell facing the same way, 3 cm apart (as in a roll), from parts
  // that are 2 m apart in the rest mesh. A point between them, first near the lower
  // layer (above it: +), then near the upper one (below it: -), flips sign without
  // passing through anything; one that goes from above the lower layer to below it
  // crosses.
  const TriMesh rest = joined(sheet(10, 1.0, 0.0), sheet(10, 1.0, 0.0, 2.0, 0.0));
  ShellSurface surf(rest, 2 * dx, 2 * dx, 1e-3 * dx);
  surf.set_frame(joined(sheet(10, 1.0, 0.0), sheet(10, 1.0, 0.03)));
  const std::vector<int> id = {0};
  CHECK(count_crossings(surf, surf, std::vector<V3>{V3(0.01, 0.005, 0)}, id,
                        std::vector<V3>{V3(0.01, 0.025, 0)}, id, 4 * dx) == 0);
  CHECK(count_crossings(surf, surf, std::vector<V3>{V3(0.01, 0.005, 0)}, id,
                        std::vector<V3>{V3(0.01, -0.005, 0)}, id, 4 * dx) == 1);
}

TEST_CASE("crossing checks: collider depth from the analytic shape at the frame's time",
          "[stress_checks]") {
  ColliderShape plane;
  plane.kind = ColliderShape::Kind::Plane;
  plane.point = V3(0, 0.3, 0);
  plane.normal = V3(0, -1, 0);  // a plate: material stays below it
  plane.keys = {{0.0, V3(0, 0, 0), V3(0, 0, 0)}, {1.0, V3(0, -0.2, 0), V3(0, 0, 0)}};
  CHECK(collider_distance(plane, V3(0, 0.25, 0), 0.0) == Approx(0.05));
  CHECK(collider_distance(plane, V3(0, 0.25, 0), 0.5) == Approx(-0.05));  // plate at 0.2
  CHECK(collider_distance(plane, V3(0, 0.25, 0), 3.0) == Approx(-0.15));  // held after the keys
  ColliderShape box;
  box.kind = ColliderShape::Kind::Box;
  box.min = V3(-0.1, -0.1, -0.1);
  box.max = V3(0.1, 0.1, 0.1);
  box.keys = {{0.0, V3(1, 0, 0), V3(0, 0, 45)}};
  CHECK(collider_distance(box, V3(1, 0, 0), 0.0) == Approx(-0.1));
  // 0.1 along the box's diagonal: 0.1 / sqrt 2 along each local axis, inside.
  CHECK(collider_distance(box, V3(1.1, 0, 0), 0.0) ==
        Approx(0.1 / std::sqrt(2.0) - 0.1).margin(1e-12));
  ColliderShape ball;
  ball.kind = ColliderShape::Kind::Sphere;
  ball.center = V3(0, -0.2, 0);
  ball.radius = 0.1;
  ball.keys = {{0.0, V3(0, 0, 0), V3(0, 0, 0)}, {0.03, V3(0, 0.3, 0), V3(0, 0, 0)}};
  CHECK(collider_distance(ball, V3(0, 0, 0), 0.01) == Approx(0.0).margin(1e-12));
  CHECK(collider_distance(ball, V3(0, 0.1, 0), 0.03) == Approx(-0.1));
  ColliderShape cyl;
  cyl.kind = ColliderShape::Kind::Cylinder;
  cyl.center = V3(0, 0, 0);
  cyl.axis = V3(0, 2, 0);
  cyl.radius = 0.1;
  cyl.height = 0.4;
  CHECK(collider_distance(cyl, V3(0.05, 0.1, 0), 0) == Approx(-0.05));
  CHECK(collider_distance(cyl, V3(0, 0.3, 0), 0) == Approx(0.1));
}

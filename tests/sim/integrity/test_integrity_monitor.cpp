// The integrity monitor (sim/integrity/integrity_monitor.h) on states with known answers:
// points moved through a sheet, round its rim, shells pushed through each other and
// folded through themselves, points inside a collider, non-finite values.
#include <catch2/catch.hpp>

#include "sim/integrity/integrity_monitor.h"
#include "sim/math/triangle_queries.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

constexpr double kDx = 0.02;

std::unique_ptr<ShellObject> flat_sheet(const std::string& name, double size, int res, double y) {
  ShellDesc d;
  d.name = name;
  d.kind = ShellDesc::Kind::Sheet;
  d.size[0] = d.size[1] = size;
  d.resolution[0] = d.resolution[1] = res;
  d.translate = Vec3d(0, y, 0);
  return std::make_unique<ShellObject>(d, test::cloth_material(), build_shell_rest_mesh(d));
}

}  // namespace

TEST_CASE("triangle queries: closest points and segment crossings", "[integrity]") {
  const Vec3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  Vec3d w = closest_point_barycentric(Vec3d(0.2, 0.3, 0.5), a, b, c);
  CHECK((w - Vec3d(0.5, 0.2, 0.3)).norm() < 1e-12);
  w = closest_point_barycentric(Vec3d(2, -1, 0), a, b, c);  // beyond corner b
  CHECK((w - Vec3d(0, 1, 0)).norm() < 1e-12);
  w = closest_point_barycentric(Vec3d(0.5, -3, 1), a, b, c);  // beside edge ab
  CHECK((w - Vec3d(0.5, 0.5, 0)).norm() < 1e-12);
  CHECK(segment_crosses_triangle(Vec3d(0.2, 0.2, -1), Vec3d(0.2, 0.2, 1), a, b, c));
  CHECK_FALSE(segment_crosses_triangle(Vec3d(0.2, 0.2, 0.1), Vec3d(0.2, 0.2, 1), a, b, c));
  CHECK_FALSE(segment_crosses_triangle(Vec3d(0.8, 0.8, -1), Vec3d(0.8, 0.8, 1), a, b, c));
  CHECK_FALSE(segment_crosses_triangle(Vec3d(-1, 0.2, 0), Vec3d(2, 0.2, 0), a, b, c));  // in plane
}

TEST_CASE("the monitor counts points that cross a sheet, not those going round its rim",
          "[integrity]") {
  auto sheet = flat_sheet("film", 0.4, 20, 0.0);
  ParticleSet bulk;
  for (int i = 0; i < 5; ++i)  // above the middle of the sheet
    bulk.push_back(Vec3(-0.05f + 0.02f * i, 0.01f, 0.0f), Vec3::Zero(), 1e-6f, 0, 1);
  bulk.push_back(Vec3(0.19f, 0.01f, 0.0f), Vec3::Zero(), 1e-6f, 0, 1);  // at the rim
  IntegrityView view;
  view.bulk = &bulk;
  view.shells = {sheet.get()};
  IntegrityMonitor mon;
  mon.setup(view, kDx);
  REQUIRE(mon.active());
  mon.begin_frame(view);
  // Three particles go through in steps of 0.6 dx (within the band each time).
  for (int step = 0; step < 3; ++step) {
    for (int i = 0; i < 3; ++i) bulk.x[i].y() -= 0.012f;
    mon.track(view);
  }
  // The rim particle goes round the edge: out past the rim, then under the sheet.
  bulk.x[5] = Vec3(0.23f, 0.0f, 0.0f);
  mon.track(view);
  bulk.x[5] = Vec3(0.19f, -0.01f, 0.0f);
  const IntegrityReport r = mon.end_frame(view);
  CHECK(r.bulk_crossings == 3);
  CHECK(r.failed());
  REQUIRE(!r.events.empty());
  CHECK(r.events[0].object == "film");
  CHECK(r.events[0].kind == IntegrityEvent::Kind::BulkThroughShell);
  // The next frame starts from the crossed state: nothing new.
  mon.begin_frame(view);
  const IntegrityReport next = mon.end_frame(view);
  CHECK(next.bulk_crossings == 0);
  CHECK_FALSE(next.failed());
  const std::vector<std::string> lines = describe_integrity(r, 4, kDx);
  REQUIRE(lines.size() == 1);
  CHECK(lines[0].find("frame 4: 3 bulk particles crossed shell 'film'") == 0);
}

TEST_CASE("the monitor finds shells through each other and a sheet folded through itself",
          "[integrity]") {
  auto a = flat_sheet("a", 0.4, 20, 0.0);
  auto b = flat_sheet("b", 0.4, 20, 0.03);
  IntegrityView view;
  view.shells = {a.get(), b.get()};
  IntegrityMonitor mon;
  mon.setup(view, kDx);
  mon.begin_frame(view);
  IntegrityReport r = mon.end_frame(view);
  CHECK(r.shell_crossing_edges == 0);
  CHECK(r.shell_point_crossings == 0);
  // Sheet b sinks through a in steps of half a cell, its middle first.
  mon.begin_frame(view);
  for (int step = 0; step < 6; ++step) {
    for (Vec3& x : b->x) x.y() -= 0.01f;
    mon.track(view);
  }
  // Tilt b so that it pierces a: edges of one through the other at the frame's end.
  for (Vec3& x : b->x) x.y() = 0.5f * x.x();
  r = mon.end_frame(view);
  CHECK(r.shell_point_crossings > 0);
  CHECK(r.shell_crossing_edges > 0);
  // A lone sheet whose half is folded straight down through the other half's plane.
  auto c = flat_sheet("c", 0.4, 20, 0.0);
  IntegrityView one;
  one.shells = {c.get()};
  IntegrityMonitor mc;
  mc.setup(one, kDx);
  CHECK(mc.snapshot(one).self_crossing_edges == 0);
  for (std::size_t j = 0; j < c->size(); ++j) {
    Vec3& x = c->x[j];
    if (x.x() > 0.05f) x = Vec3(-0.1f, -(x.x() - 0.05f) + 0.1f, x.z());  // a flap through y = 0
  }
  CHECK(mc.snapshot(one).self_crossing_edges > 0);
}

TEST_CASE("the monitor reports points deeper than half a cell inside a collider, and NaNs",
          "[integrity]") {
  ColliderDesc g;
  g.name = "ground";
  g.shape.kind = ShapeDesc::Kind::Plane;
  g.shape.point = Vec3d::Zero();
  g.shape.normal = Vec3d(0, 1, 0);
  std::vector<Collider> colliders{Collider(g)};
  ParticleSet bulk;
  bulk.push_back(Vec3(0, -0.004f, 0), Vec3::Zero(), 1e-6f, 0, 1);  // 0.2 dx: tolerated
  bulk.push_back(Vec3(0, -0.016f, 0), Vec3::Zero(), 1e-6f, 0, 1);  // 0.8 dx
  bulk.push_back(Vec3(0.1f, 0.1f, 0), Vec3::Zero(), 1e-6f, 0, 1);
  IntegrityView view;
  view.bulk = &bulk;
  view.colliders = &colliders;
  IntegrityMonitor mon;
  mon.setup(view, kDx);
  IntegrityReport r = mon.snapshot(view);
  CHECK(r.collider_penetrations == 1);
  CHECK(r.max_collider_depth == Approx(0.016).epsilon(1e-5));
  REQUIRE(r.events.size() == 1);
  CHECK(r.events[0].object == "ground");
  bulk.v[2].x() = std::numeric_limits<Real>::quiet_NaN();
  r = mon.snapshot(view);
  CHECK(r.non_finite == 1);
}

TEST_CASE("a contact shell stretched past 2 dx per edge is a warning, not a failure",
          "[integrity]") {
  auto sheet = flat_sheet("curtain", 0.4, 20, 0.0);  // 2 cm edges: 1 dx
  IntegrityView view;
  view.shells = {sheet.get()};
  IntegrityMonitor mon;
  mon.setup(view, kDx);
  IntegrityReport r = mon.snapshot(view);
  CHECK(r.stretched_edges == 0);
  CHECK(r.max_edge == Approx(0.02 * std::sqrt(2.0)).epsilon(0.05));  // the diagonals
  for (Vec3& x : sheet->x) x.x() *= 2.5f;                            // edges along x now 2.5 dx
  r = mon.snapshot(view);
  CHECK(r.stretched_edges > 0);
  CHECK(r.max_edge > 2.4 * kDx);
  CHECK_FALSE(r.failed());
  REQUIRE(r.events.size() == 1);
  CHECK(r.events[0].kind == IntegrityEvent::Kind::StretchedMesh);
  const std::vector<std::string> lines = describe_integrity(r, 7, kDx);
  CHECK(lines[0].find("frame 7: shell 'curtain' has ") == 0);
  CHECK(lines[0].find("edges longer than 2 dx") != std::string::npos);
}

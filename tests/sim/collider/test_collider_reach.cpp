// Which nodes take a collider's condition (sim/collider/collider_reach.h): nodes inside a
// collider do only when material within reach of it maps to them.
#include <catch2/catch.hpp>

#include <algorithm>

#include "io/scene_reader.h"
#include "sim/collider/collider_reach.h"
#include "sim/mpm/bspline.h"
#include "sim/solver/solver.h"

using namespace shellmpm;

namespace {

constexpr double kDx = 0.02;

Collider ball() {
  ColliderDesc c;
  c.name = "ball";
  c.shape.kind = ShapeDesc::Kind::Sphere;
  c.shape.center = Vec3d(0.2, 0.25, 0.2);
  c.shape.radius = 0.04;
  c.boundary = BoundaryKind::Separate;
  Collider col(c);
  col.begin_step(0, 1e-3);
  return col;
}

/// A sheet of points at height y (spacing dx / 2) under the ball.
std::vector<Vec3> sheet(double y) {
  std::vector<Vec3> x;
  for (int i = 0; i < 24; ++i)
    for (int k = 0; k < 24; ++k)
      x.emplace_back(static_cast<Real>(0.2 + (i - 11.5) * 0.5 * kDx), static_cast<Real>(y),
                     static_cast<Real>(0.2 + (k - 11.5) * 0.5 * kDx));
  return x;
}

std::vector<Vec3> still(const std::vector<Vec3>& x) {
  return std::vector<Vec3>(x.size(), Vec3::Zero());
}

/// The nodes inside the collider whose massive stencil it marks, and the marked ones.
struct Counts {
  std::size_t inside = 0, engaged = 0, engaged_outside_reach = 0;
};

Counts count(const SparseGrid& grid, const ColliderReach& reach, const Collider& col,
             const std::vector<Vec3>& x, double r) {
  Counts c;
  for (std::size_t g = 0; g < grid.num_grid_blocks(); ++g) {
    const Vec3i corner = unpack_block(grid.gblock_key[g]) * kBlockSize;
    for (int n = 0; n < kBlockNodes; ++n) {
      const Vec3i node(corner[0] + n / 16, corner[1] + (n / 4) % 4, corner[2] + n % 4);
      if (col.phi(grid.node_position(node)) > 0) continue;
      ++c.inside;
      if (!reach.engaged(g, n, 0)) continue;
      ++c.engaged;
      // Some point within reach must have this node in its stencil.
      bool covered = false;
      for (const Vec3& p : x) {
        if (col.phi(p.cast<double>()) > r) continue;
        const QuadraticWeights W(grid.grid_coord(p));
        covered = covered || ((node - Vec3i(W.base[0], W.base[1], W.base[2])).array() >= 0 &&
                              (node - Vec3i(W.base[0], W.base[1], W.base[2])).array() < 3)
                                 .all();
      }
      if (!covered) ++c.engaged_outside_reach;
    }
  }
  return c;
}

}  // namespace

TEST_CASE("a sheet below a ball engages none of the ball's nodes until it comes within reach",
          "[collider]") {
  const Collider col = ball();
  const std::vector<Collider> cols{col};
  const double r = kColliderReachCells * kDx;
  SparseGrid grid;
  grid.setup(kDx, Vec3d::Zero());
  SECTION("1 cm below: the ball covers nodes of the sheet's stencil, none is engaged") {
    const std::vector<Vec3> x = sheet(0.20);  // the ball's bottom is at 0.21
    grid.bin(x);
    ColliderReach reach;
    reach.compute(grid, nullptr, nullptr, x, still(x), cols, r, 1e-3, false);
    const Counts c = count(grid, reach, col, x, r);
    CHECK(c.inside > 0);  // the node-only rule would act on these
    CHECK(c.engaged == 0);
    CHECK(reach.count() == 0);
    // Moving up at 12 m/s, it reaches the ball within the 1 ms step: engaged now.
    ColliderReach moving;
    moving.compute(grid, nullptr, nullptr, x, std::vector<Vec3>(x.size(), Vec3(0, 12, 0)), cols, r,
                   1e-3, false);
    CHECK(moving.count() > 0);
  }
  SECTION("touching: exactly the stencils of the points within reach") {
    const std::vector<Vec3> x = sheet(0.2115);  // 1.5 mm into the ball under its bottom
    grid.bin(x);
    ColliderReach reach, threaded;
    reach.compute(grid, nullptr, nullptr, x, still(x), cols, r, 1e-3, true);
    const Counts c = count(grid, reach, col, x, r);
    CHECK(c.engaged > 0);
    CHECK(c.engaged < c.inside);  // the ball's nodes over the sheet far from it are not
    CHECK(c.engaged_outside_reach == 0);
    // Points binned as a concatenation give the same marks, and threads change nothing.
    const std::vector<Vec3> head(x.begin(), x.begin() + 100), tail(x.begin() + 100, x.end());
    SparseGrid split;
    split.setup(kDx, Vec3d::Zero());
    split.bin(&head, tail);
    const std::vector<Vec3> hv = still(head);
    threaded.compute(split, &head, &hv, tail, still(tail), cols, r, 1e-3, false);
    REQUIRE(split.num_grid_blocks() == grid.num_grid_blocks());
    for (std::size_t g = 0; g < grid.num_grid_blocks(); ++g)
      for (int n = 0; n < kBlockNodes; ++n)
        REQUIRE(threaded.engaged(g, n, 0) == reach.engaged(g, n, 0));
  }
  SECTION("before compute, and past the 32nd collider, every node takes the condition") {
    ColliderReach reach;
    CHECK(reach.engaged(0, 0, 0));
    const std::vector<Vec3> x = sheet(0.20);
    grid.bin(x);
    std::vector<Collider> many(33, col);
    reach.compute(grid, nullptr, nullptr, x, still(x), many, r, 1e-3, false);
    CHECK_FALSE(reach.engaged(0, 0, 31));
    CHECK(reach.engaged(0, 0, 32));
  }
}

TEST_CASE("a ball struck at a steel sheet moves it only once it touches it", "[collider][solver]") {
  // scenes/steel_dent.yaml: the ball's bottom starts 1 cm above the sheet (half a cell at
  // dx 2 cm) and comes down at 10 m/s. With every node inside the ball taking its
  // condition, the ball reached the sheet through the nodes above it at once and had
  // pushed it 3.2 mm down by t = 0.42 ms, long before touching it at 1 ms. Now it starts
  // to push when it comes within reach (0.1 dx, 2 mm), at 0.8 ms.
  Scene s = read_scene(std::string(SHELLMPM_SOURCE_DIR) + "/scenes/steel_dent.yaml");
  s.shot.fps = 2400;
  Solver solver(s);
  const auto lowest = [&] {
    double low = 1e9;
    for (const Vec3& x : solver.shells()[0]->x) low = std::min(low, static_cast<double>(x.y()));
    return low;
  };
  solver.advance_to(0.0007);  // the ball's bottom at 0.103 m
  INFO("lowest control point at 0.7 ms " << lowest() << " m");
  CHECK(lowest() > 0.1 - 1e-5);
  FrameStats fs = solver.advance_to(0.0015);  // 5 mm past the sheet's plane
  INFO("at 1.5 ms " << lowest() << " m");
  CHECK(lowest() < 0.1 - 2e-3);  // and it does push it once they touch
  CHECK(!fs.integrity.failed());
}

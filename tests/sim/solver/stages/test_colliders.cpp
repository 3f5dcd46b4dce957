// The collider stage (sim/solver/stages/colliders.cpp) against the domain walls: a ground
// plane close to the domain's edge, inside the band of nodes the walls hold, must still
// apply its own friction.
#include <catch2/catch.hpp>
#include <cmath>

#include "sim/solver/solver.h"
#include "tests/support/bulk_fixtures.h"

using namespace shellmpm;

namespace {

// A sand block 0.1 x 0.04 x 0.06 m resting on a ground plane at y = 0 and sliding along x
// at 1 m/s, the domain's floor `below` metres under the ground, dx 0.02.
Scene sliding_sand(double below, double friction, BoundaryKind boundary) {
  Scene s;
  s.path = "test";
  s.shot.dx = 0.02;
  s.shot.fps = 24;
  s.shot.domain_min = Vec3d(-0.1, -below, -0.1);
  s.shot.domain_max = Vec3d(0.7, 0.2, 0.1);
  s.materials.push_back(test::sand_material(1e5, 32));
  SourceDesc block;
  block.shape.kind = ShapeDesc::Kind::Box;
  block.shape.min = Vec3d(0.0, 0.0, -0.03);
  block.shape.max = Vec3d(0.1, 0.04, 0.03);
  block.velocity = Vec3d(1, 0, 0);
  s.sources.push_back(block);
  ColliderDesc ground;
  ground.shape.kind = ShapeDesc::Kind::Plane;
  ground.shape.point = Vec3d(0, 0, 0);
  ground.shape.normal = Vec3d(0, 1, 0);
  ground.boundary = boundary;
  ground.friction = friction;
  s.colliders.push_back(ground);
  return s;
}

// Mean velocity along x after each of the first `frames` frames.
std::vector<double> slide_speeds(const Scene& s, int frames) {
  Solver solver(s);
  std::vector<double> v;
  for (int f = 1; f <= frames; ++f) {
    const FrameStats fs = solver.advance_to(f / 24.0);
    v.push_back(fs.momentum.x() / fs.mass);
  }
  return v;
}

}  // namespace

TEST_CASE("a rough ground inside the domain walls' band still brakes a sliding block by Coulomb",
          "[colliders][solver][sand]") {
  // The walls hold the normal velocity of nodes within kWallCells (3) cells of the domain's
  // edge. Ground 2 cells (on a node row) and 2.5 cells (between rows) above that edge: both
  // inside the band. Before the colliders ran first, the frictionless wall zeroed the
  // velocity into the ground and the block slid on as if on ice (1.0 m/s after 3 frames).
  const double mu = 0.6, g = 9.81;
  for (double below : {0.04, 0.05, 0.2}) {  // 0.2: far from the walls, the control
    CAPTURE(below);
    const std::vector<double> v = slide_speeds(sliding_sand(below, mu, BoundaryKind::Separate), 4);
    // Deceleration over frames 1 to 4 (the block has settled onto the ground by frame 1).
    const double decel = (v[0] - v[3]) / (3.0 / 24);
    CHECK(decel == Approx(mu * g).epsilon(0.15));
    // Without friction it keeps its speed: the braking above is the ground's friction.
    const std::vector<double> free =
        slide_speeds(sliding_sand(below, 0, BoundaryKind::Separate), 4);
    CHECK(free[3] > 0.97);
  }
}

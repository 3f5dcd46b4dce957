// Shells without contact (no grid) meet colliders through their control points: the
// projection after each step (collider_particles stage) and, implicit, the step's penalty
// (sim/implicit/collider_penalty.h). Before, such a shell fell through every collider.
#include <catch2/catch.hpp>
#include <cmath>

#include "sim/solver/solver.h"
#include "sim/solver/stages/registry.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

/// A free 0.3 m cloth (contact off) 5 cm above a ball of radius 0.1 m at the origin.
Scene cloth_over_ball(Integrator integrator) {
  Scene s = test::contact_test_scene(0.02);
  s.shot.fps = 24;
  s.shot.integrator = integrator;
  if (integrator == Integrator::Implicit) s.shot.dt_max = 1.0 / 240;
  s.shell_materials.push_back(test::cloth_material());
  ShellDesc sh = test::free_sheet("cloth", 0.3, 8);
  sh.translate = Vec3d(0, 0.15, 0);
  s.shells.push_back(sh);
  ColliderDesc ball = test::sphere_collider("ball", Vec3d::Zero(), 0.1);
  ball.friction = 0.5;
  s.colliders.push_back(ball);
  return s;
}

}  // namespace

TEST_CASE("a shell without contact projects onto colliders (stage list)", "[collider]") {
  const std::vector<std::string> names = stage_names(cloth_over_ball(Integrator::Explicit));
  CHECK(std::find(names.begin(), names.end(), "collider_particles") != names.end());
  CHECK(std::find(names.begin(), names.end(), "p2g") == names.end());  // still no grid
}

TEST_CASE("a shell without contact drapes over a collider instead of falling through it",
          "[collider]") {
  for (const Integrator integ : {Integrator::Explicit, Integrator::Implicit}) {
    const Scene s = cloth_over_ball(integ);
    Solver solver(s);
    solver.advance_to(0.5);  // free fall of 5 cm takes 0.1 s
    const ShellObject& sh = *solver.shells()[0];
    const Collider& ball = solver.colliders()[0];
    double deepest = 0, centre = -1, lowest = 1;
    for (std::size_t i = 0; i < sh.size(); ++i) {
      const Vec3d x = sh.x[i].cast<double>();
      deepest = std::min(deepest, ball.phi(x));
      if (std::hypot(x.x(), x.z()) < 0.02) centre = std::max(centre, x.y());
      lowest = std::min(lowest, x.y());
    }
    INFO((integ == Integrator::Explicit ? "explicit" : "implicit")
         << ": deepest " << deepest << " m, centre " << centre << " m, lowest " << lowest);
    CHECK(deepest > -1e-4);                     // no control point inside the ball
    CHECK(centre == Approx(0.1).margin(0.01));  // resting on its top
    CHECK(lowest < 0.07);                       // and draped: the corners hang down
    CHECK(lowest > -0.2);
  }
}

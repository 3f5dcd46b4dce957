// The output (limit) mesh's velocities: the position map applied to the control-point
// velocities, so they are the time derivative of the output positions.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "sim/shell/shell_object.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

/// A curved shell (every output vertex mixes several control points with unequal weights).
ShellObject make_sphere_shell() {
  ShellDesc sh;
  sh.name = "ball";
  sh.kind = ShellDesc::Kind::Sphere;
  sh.radius = 0.3;
  sh.subdivisions = 1;
  sh.output_refine = 2;
  return ShellObject(sh, test::cloth_material(), build_shell_rest_mesh(sh));
}

}  // namespace

TEST_CASE("output velocities are the derivative of the output positions", "[shell][velocity]") {
  ShellObject o = make_sphere_shell();
  const std::size_t nc = o.size();
  // A non-rigid control velocity field: each point moves differently.
  for (std::size_t i = 0; i < nc; ++i) {
    const Vec3 x = o.x[i];
    o.v[i] = Vec3(std::sin(Real(3) * x.y()) + Real(0.1) * i, x.x() * x.z() * Real(4),
                  Real(-1) + Real(0.02) * i);
  }
  std::vector<Vec3> pos, nrm, vel;
  o.output_mesh(pos, nrm);
  o.output_velocity(vel);
  REQUIRE(vel.size() == pos.size());
  REQUIRE(vel.size() == o.limit_mesh().num_vertices());

  // Central difference of the positions along the velocity (the map is linear, so only
  // rounding separates them).
  const Real h = Real(1e-2);
  std::vector<Vec3> xp(nc), xm(nc), pp, pm, unused;
  for (std::size_t i = 0; i < nc; ++i) {
    xp[i] = o.x[i] + h * o.v[i];
    xm[i] = o.x[i] - h * o.v[i];
  }
  o.limit_mesh().evaluate(xp.data(), pp, unused);
  o.limit_mesh().evaluate(xm.data(), pm, unused);
  double worst = 0, largest = 0;
  for (std::size_t r = 0; r < vel.size(); ++r) {
    const Vec3d fd = ((pp[r] - pm[r]) / (2 * h)).cast<double>();
    worst = std::max(worst, (fd - vel[r].cast<double>()).norm());
    largest = std::max(largest, vel[r].cast<double>().norm());
  }
  INFO("max |finite difference - velocity| " << worst << " m/s, max |v| " << largest);
  CHECK(largest > 0.5);
  CHECK(worst < 1e-4 * largest);

  // Rigid motions are reproduced exactly (up to rounding): weights sum to one, and the
  // map commutes with cross products by a constant vector.
  const Vec3 u(Real(0.3), Real(-0.2), Real(0.1)), w(Real(0.5), Real(2), Real(-1));
  for (std::size_t i = 0; i < nc; ++i) o.v[i] = u + w.cross(o.x[i]);
  o.output_velocity(vel);
  double rigid = 0;
  for (std::size_t r = 0; r < vel.size(); ++r)
    rigid = std::max(rigid, (vel[r] - (u + w.cross(pos[r]))).cast<double>().norm());
  INFO("rigid motion: max error " << rigid << " m/s");
  CHECK(rigid < 1e-5);
}

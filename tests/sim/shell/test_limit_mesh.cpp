// The output (limit) mesh: its velocities are the position map applied to the control-point
// velocities, so they are the time derivative of the output positions; and it splits its
// vertices at UV seams.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "sim/shell/procedural_mesh.h"
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

TEST_CASE("the output mesh splits at UV seams and only there; copies share their row",
          "[shell][uv]") {
  // A closed tube whose UVs run once around: the column of points at u = 0 gets a second
  // UV entry (u = 1) on the triangles of the last strip, as a mesh file with a seam reads.
  const int around = 6, along = 3;
  ShellMesh tube = make_cylinder(0.2, 0.3, 360, around, along);
  const std::size_t nv = tube.vertices.size();
  REQUIRE(nv == static_cast<std::size_t>(around * (along + 1)));
  tube.uvs.clear();
  for (int j = 0; j <= along; ++j)
    for (int i = 0; i <= around; ++i) tube.uvs.emplace_back(double(i) / around, double(j) / along);
  // Control point (i, j) = j * around + i; UV entry (i, j) = j * (around + 1) + i.
  tube.uv_triangles.clear();
  for (std::size_t t = 0; t < tube.triangles.size(); ++t) {
    const Eigen::Vector3i& f = tube.triangles[t];
    const int strip = static_cast<int>(t / 2) % around;  // quad i = strip
    Eigen::Vector3i u;
    for (int k = 0; k < 3; ++k) {
      const int i = f[k] % around, j = f[k] / around;
      // The last strip's corners at i = 0 are its right-hand edge: u = 1.
      const int iu = (strip == around - 1 && i == 0) ? around : i;
      u[k] = j * (around + 1) + iu;
    }
    tube.uv_triangles.push_back(u);
  }
  const LoopBasis basis(static_cast<int>(nv), tube.triangles);
  for (int levels = 0; levels <= 2; ++levels) {
    CAPTURE(levels);
    const LimitMesh plain(basis, tube.triangles, {}, levels);
    const LimitMesh seamed(basis, tube.triangles, tube.uvs, tube.uv_triangles, levels);
    // The seam is along + 1 points and, refined, (2^levels - 1) more per seam edge.
    const std::size_t seam_points = (along + 1) + along * ((std::size_t(1) << levels) - 1);
    CHECK(seamed.num_vertices() == plain.num_vertices() + seam_points);
    REQUIRE(seamed.uvs().size() == seamed.num_vertices());
    REQUIRE(seamed.triangles().size() == plain.triangles().size());
    // Same surface: evaluated at the rest pose, each seamed triangle has the same corner
    // positions as the plain one, and copies of a point are the same row bit for bit.
    std::vector<Vec3> x(nv), pp, pn, sp, sn;
    for (std::size_t i = 0; i < nv; ++i) x[i] = tube.vertices[i].cast<Real>();
    plain.evaluate(x.data(), pp, pn);
    seamed.evaluate(x.data(), sp, sn);
    const std::size_t per = std::size_t(1) << (2 * levels);
    for (std::size_t t = 0; t < seamed.triangles().size(); ++t)
      for (int k = 0; k < 3; ++k) {
        const int a = plain.triangles()[t][k], b = seamed.triangles()[t][k];
        REQUIRE(sp[b] == pp[a]);
        REQUIRE(sn[b] == pn[a]);
        REQUIRE(seamed.row_points(b) == plain.row_points(a));
        // The UV comes from this triangle's control triangle: within its UV triangle's
        // u range, so no triangle of the last strip reads u = 0 where it should read 1.
        const Eigen::Vector3i& ut = tube.uv_triangles[t / per];
        double lo = 1e9, hi = -1e9;
        for (int c = 0; c < 3; ++c) {
          lo = std::min(lo, tube.uvs[ut[c]].x());
          hi = std::max(hi, tube.uvs[ut[c]].x());
        }
        CHECK(seamed.uvs()[b].x() >= lo - 1e-12);
        CHECK(seamed.uvs()[b].x() <= hi + 1e-12);
      }
    // Without the seam the plain mesh is what a per-vertex UV table gives: no split.
    const LimitMesh per_vertex(basis, tube.triangles,
                               std::vector<Eigen::Vector2d>(nv, Eigen::Vector2d::Zero()), levels);
    CHECK(per_vertex.num_vertices() == plain.num_vertices());
  }
}

#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <limits>

#include "sim/core/parallel.h"
#include "sim/solver/solver.h"
#include "tests/support/bulk_fixtures.h"

using namespace shellmpm;

namespace {

Scene block_scene() {
  Scene s;
  s.path = "test";
  s.shot.dx = 0.05;
  s.shot.domain_min = Vec3d(-2, -2, -2);
  s.shot.domain_max = Vec3d(2, 4, 2);
  s.shot.fps = 24;
  MaterialDesc m;
  m.name = "jelly";
  m.youngs_modulus = 2e4;
  m.density = 1000;
  s.materials.push_back(m);
  SourceDesc src;
  src.shape.kind = ShapeDesc::Kind::Box;
  src.shape.min = Vec3d(-0.2, 2.0, -0.2);
  src.shape.max = Vec3d(0.2, 2.4, 0.2);
  src.velocity = Vec3d(0.5, 1.0, 0.0);
  s.sources.push_back(src);
  return s;
}

Vec3d center_of_mass(const ParticleSet& p) {
  Vec3d c = Vec3d::Zero();
  double m = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    c += double(p.volume_of(i)) * p.x[i].cast<double>();
    m += p.volume_of(i);
  }
  return c / m;
}

}  // namespace

TEST_CASE("a block in free fall follows x0 + v0 t + g t^2 / 2", "[solver]") {
  Scene s = block_scene();
  Solver solver(s);
  const Vec3d x0 = center_of_mass(solver.particles());
  const Vec3d v0 = s.sources[0].velocity, g = s.shot.gravity;
  double dt_max = 0;
  for (int f = 1; f <= 12; ++f) {
    const FrameStats fs = solver.advance_to(f / 24.0);
    dt_max = std::max(dt_max, fs.dt_max);
    const double t = solver.time();
    const Vec3d expect = x0 + v0 * t + 0.5 * g * t * t;
    // Symplectic Euler is off by g t dt / 2 at most; float round-off adds a little.
    const double tol = 0.5 * g.norm() * t * dt_max + 1e-4;
    REQUIRE((center_of_mass(solver.particles()) - expect).norm() < tol);
    REQUIRE(fs.elastic_energy < 1e-6);  // no internal deformation in free fall
  }
}

TEST_CASE("substeps end on the frame's end, not a round-off before it", "[solver]") {
  // Eleven equal steps of a 1/12 s frame sum to 1.4e-17 s short of it: without the snap a
  // twelfth step of that length would follow.
  const double t_end = 1.0 / 12, dt = t_end / 11;
  double t = 0, naive = 0;
  int steps = 0;
  while (t < t_end && steps < 20) {
    t = step_end_time(t, dt, t_end, false);
    naive += dt;
    ++steps;
  }
  CHECK(naive < t_end);  // the sum alone falls short
  CHECK(steps == 11);
  CHECK(t == t_end);
  // A step that is really short of the end stays short.
  CHECK(step_end_time(0, 0.5 * t_end, t_end, false) == 0.5 * t_end);
  CHECK(step_end_time(0.25, 0.5, 1.0, true) == 1.0);
}

TEST_CASE("a falling block stops on a ground plane collider", "[solver][collider]") {
  Scene s = block_scene();
  ColliderDesc ground;
  ground.shape.kind = ShapeDesc::Kind::Plane;
  ground.shape.point = Vec3d(0, 1.5, 0);
  ground.boundary = BoundaryKind::Sticky;
  s.colliders.push_back(ground);
  s.sources[0].velocity = Vec3d(0, -2, 0);
  Solver solver(s);
  REQUIRE(solver.stage_names() ==
          std::vector<std::string>{"bin", "p2g", "grid", "colliders", "g2p", "collider_particles"});
  // Before contact: free fall. Contact begins when the bottom (y = 2.0) reaches ~1.5 + dx.
  const FrameStats early = solver.advance_to(0.1);
  const double t = solver.time();
  const double expect_y = 2.2 - 2 * t - 0.5 * 9.81 * t * t;
  REQUIRE(center_of_mass(solver.particles()).y() == Approx(expect_y).margin(0.01));
  (void)early;
  // Total energy (kinetic + elastic + gravitational) never grows: the block bounces on
  // the sticky plane, losing energy, and never passes through it.
  auto total_energy = [&] {
    FrameStats fs;
    solver.measure(fs);
    double pe = 0;
    const ParticleSet& p = solver.particles();
    for (std::size_t i = 0; i < p.size(); ++i)
      pe += double(p.volume_of(i)) * 1000 * 9.81 * p.x[i].y();
    return fs.kinetic_energy + fs.elastic_energy + pe;
  };
  Solver fresh(s);
  FrameStats f0;
  fresh.measure(f0);
  double pe0 = 0;
  for (std::size_t i = 0; i < fresh.particles().size(); ++i)
    pe0 += double(fresh.particles().volume_of(i)) * 1000 * 9.81 * fresh.particles().x[i].y();
  const double e0 = f0.kinetic_energy + pe0;
  double ymin = 1e9, emax = 0;
  for (int f = 1; f <= 36; ++f) {
    solver.advance_to(0.1 + f / 24.0);
    for (const Vec3& x : solver.particles().x) ymin = std::min(ymin, double(x.y()));
    emax = std::max(emax, total_energy());
  }
  REQUIRE(ymin > 1.5 - 0.5 * s.shot.dx);  // never through the plane
  REQUIRE(emax < e0 * 1.01);
  REQUIRE(total_energy() < e0 - 0.2 * f0.kinetic_energy);  // the sticky impact dissipated
}

TEST_CASE("a sand column collapses and comes to rest with no particle lost", "[solver][sand]") {
  Scene s;
  s.path = "test";
  s.shot.dx = 0.02;
  s.shot.domain_min = Vec3d(-0.5, 0, -0.5);
  s.shot.domain_max = Vec3d(0.5, 0.5, 0.5);
  s.materials.push_back(test::sand_material(3e4, 35));
  SourceDesc col;
  col.shape.kind = ShapeDesc::Kind::Box;
  col.shape.min = Vec3d(-0.06, 0.06, -0.06);
  col.shape.max = Vec3d(0.06, 0.36, 0.06);
  s.sources.push_back(col);
  ColliderDesc ground;
  ground.shape.kind = ShapeDesc::Kind::Plane;
  ground.shape.point = Vec3d(0, 0.06, 0);
  ground.boundary = BoundaryKind::Sticky;
  s.colliders.push_back(ground);
  Solver solver(s);
  REQUIRE(solver.stage_names() == std::vector<std::string>{"bin", "p2g", "grid", "colliders", "g2p",
                                                           "collider_particles", "plasticity"});
  const std::size_t n0 = solver.particles().size();
  FrameStats fs0;
  solver.measure(fs0);
  FrameStats fs;
  for (int f = 1; f <= 36; ++f) fs = solver.advance_to(f / 24.0);
  REQUIRE(solver.particles().size() == n0);
  REQUIRE(fs.mass == Approx(fs0.mass).epsilon(1e-6));
  double ymax = 0, rmax = 0;
  for (const Vec3& x : solver.particles().x) {
    for (int a = 0; a < 3; ++a) {
      REQUIRE(x[a] >= s.shot.domain_min[a]);
      REQUIRE(x[a] <= s.shot.domain_max[a]);
    }
    REQUIRE(std::isfinite(x.x()));
    ymax = std::max(ymax, double(x.y()));
    rmax = std::max(rmax, std::hypot(double(x.x()), double(x.z())));
  }
  REQUIRE(ymax < 0.26);          // the column (0.30 tall) has slumped
  REQUIRE(rmax > 0.12);          // and spread beyond its initial half-width (0.085 diagonal)
  REQUIRE(fs.max_speed < 0.05);  // at rest
  REQUIRE(fs.kinetic_energy < 1e-4 * fs0.mass * 9.81 * 0.3);
}

TEST_CASE("solver runs are bit-identical for 1 and 2 threads", "[solver][determinism]") {
  Scene s = block_scene();
  ColliderDesc ball;
  ball.shape.kind = ShapeDesc::Kind::Sphere;
  ball.shape.center = Vec3d(0, 1.6, 0);
  ball.shape.radius = 0.3;
  ball.friction = 0.4;
  s.colliders.push_back(ball);
  s.sources[0].velocity = Vec3d(0.1, -3, 0);
  auto run = [&](int threads) {
    ThreadLimit lim(threads);
    Solver solver(s);
    for (int f = 1; f <= 6; ++f) solver.advance_to(f / 24.0);
    return solver.particles();
  };
  const ParticleSet a = run(1), b = run(2);
  REQUIRE(a.size() == b.size());
  REQUIRE(std::memcmp(a.x.data(), b.x.data(), a.size() * sizeof(Vec3)) == 0);
  REQUIRE(std::memcmp(a.F.data(), b.F.data(), a.size() * sizeof(Mat3)) == 0);
  REQUIRE(std::memcmp(a.C.data(), b.C.data(), a.size() * sizeof(Mat3)) == 0);
}

TEST_CASE("stages follow the scene: nothing to simulate gives no stages", "[solver]") {
  Scene s = block_scene();
  s.sources.clear();
  Solver empty(s);
  REQUIRE(empty.stage_names().empty());
  s = block_scene();
  s.sources[0].emit = true;
  s.sources[0].emit_start = 1;
  s.sources[0].emit_end = 2;
  s.materials[0].kind = MaterialKind::Snow;
  Solver snow(s);
  REQUIRE(snow.stage_names() ==
          std::vector<std::string>{"bin", "p2g", "grid", "g2p", "plasticity", "emit"});
  REQUIRE(snow.particles().size() == 0);  // emitting sources start empty
}

TEST_CASE("a non-finite velocity stops the run with a divergence error, not a crash", "[solver]") {
  Scene s = block_scene();
  Solver solver(s);
  solver.advance_to(1.0 / 24);
  REQUIRE(std::isfinite(solver.stable_dt()));
  solver.particles().v[3] = Vec3(std::numeric_limits<Real>::quiet_NaN(), 0, 0);
  CHECK(std::isnan(solver.stable_dt()));
  try {
    solver.advance_to(2.0 / 24);
    FAIL("no error");
  } catch (const SimulationError& e) {
    CHECK(std::string(e.what()).find("diverged") != std::string::npos);
  }
}

// Backward Euler for shells without contact (sim/implicit/shell_step.h, the
// implicit_shells stage): the objective's gradient, large steps against the static
// solution, small steps against the explicit integrator, momentum and energy.
#include <catch2/catch.hpp>
#include <cmath>

#include "io/scene_reader.h"
#include "sim/implicit/shell_step.h"
#include "sim/solver/solver.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

/// The cantilevered strip of scenes/study/cantilever_gravity.yaml: L = 0.2 m, b = 0.05 m,
/// t = 2 mm, E = 1e9 Pa, nu = 0, clamped over the rows x <= h (n = 16).
Scene cantilever_scene() {
  Scene s = test::contact_test_scene(0.02);
  s.shot.fps = 24;
  ShellMaterialDesc m;
  m.name = "strip";
  m.youngs_modulus = 1e9;
  m.poisson_ratio = 0.0;
  m.density = 1000;
  m.thickness = 0.002;
  s.shell_materials.push_back(m);
  const ShellDesc sh = test::clamped_strip("strip");
  s.shells.push_back(sh);
  return s;
}

/// A 0.3 m cloth held at two corners (a swing under gravity).
Scene cloth_scene() {
  Scene s = test::contact_test_scene(0.02);
  s.shot.fps = 24;
  s.shell_materials.push_back(test::cloth_material());
  ShellDesc sh;
  sh.name = "cloth";
  sh.contact = ShellDesc::Contact::Off;
  sh.kind = ShellDesc::Kind::Sheet;
  sh.size[0] = 0.3;
  sh.size[1] = 0.3;
  sh.resolution[0] = 8;
  sh.resolution[1] = 8;
  PinDesc corners;
  corners.indices = {0, 8};  // the two corners of the first row
  sh.pins.push_back(corners);
  s.shells.push_back(sh);
  return s;
}

/// s with the implicit integrator, steps of at most dt_max and the Newton tolerance tol.
Scene implicit(Scene s, double dt_max, double tol = 1e-4) {
  s.shot.integrator = Integrator::Implicit;
  s.shot.dt_max = dt_max;
  s.shot.implicit_tolerance = tol;
  return s;
}

/// Largest downward deflection over the control points [m].
double max_sag(const ShellObject& sh) {
  double w = 0;
  for (std::size_t i = 0; i < sh.size(); ++i)
    w = std::max(w, sh.rest[i].y() - static_cast<double>(sh.x[i].y()));
  return w;
}

/// Kinetic + elastic + gravitational potential energy [J], the elastic part in double (the
/// float kernel's rounding, about 1e-8 J on the stiff strip, would hide the dissipation).
double total_energy(const ShellObject& sh, const Vec3d& g) {
  std::vector<Vec3d> x(sh.size());
  for (std::size_t i = 0; i < sh.size(); ++i) x[i] = sh.x[i].cast<double>();
  double e = sh.kinetic_energy() + sh.double_kl()->energy(x.data(), nullptr).total;
  for (std::size_t i = 0; i < sh.size(); ++i) e -= static_cast<double>(sh.mass[i]) * g.dot(x[i]);
  return e;
}

}  // namespace

TEST_CASE("implicit shell: the objective's gradient matches finite differences", "[implicit]") {
  const double theta = GENERATE(1.0, 0.6);  // backward Euler, and the theta method
  CAPTURE(theta);
  Scene s = cantilever_scene();
  s.shell_materials[0].damping = 2.0;
  s.shell_materials[0].stiffness_damping = 1e-4;
  Solver solver(s);
  ShellObject& sh = *solver.shells()[0];
  // A bent state with a velocity field, so every term is active.
  for (std::size_t i = 0; i < sh.size(); ++i) {
    if (sh.pin_mask[i]) continue;
    const double x = static_cast<double>(sh.x[i].x());
    sh.x[i].y() -= static_cast<Real>(0.05 * x * x);
    sh.v[i] = Vec3(Real(0.1 * std::sin(20 * x)), Real(-0.3 * x), Real(0.05));
  }
  // A ball whose surface cuts the strip's tip, so the collider penalty acts on some of
  // the moved control points (and not on others).
  std::vector<Collider> colliders{
      Collider(test::sphere_collider("ball", Vec3d(0.2, 0.03, 0), 0.04))};
  colliders[0].begin_step(0.0, 1.0 / 24);
  ShellImplicitStep step(sh);
  VecXd u0;
  const auto obj = step.objective(sh, s.shot.gravity, 0.0, 1.0 / 24, theta,
                                  ImplicitPreconditioner::Factorised, true, u0, &colliders);
  VecXd u = u0, d(u0.size()), g;
  for (Eigen::Index k = 0; k < u.size(); ++k) d[k] = std::cos(0.7 * k);
  obj->project(d);
  u += 0.01 * d;
  int inside = 0;
  for (std::size_t i = 0; i < sh.size(); ++i)
    if (colliders[0].phi(sh.x[i].cast<double>() +
                         ((1 - theta) * sh.v[i].cast<double>() + theta * u.segment<3>(3 * i)) /
                             24) < 0)
      ++inside;
  CHECK(inside > 0);
  CHECK(inside < static_cast<int>(sh.size()) / 2);
  obj->gradient(u, g);
  const double slope = g.dot(d);
  double prev_err = 1e300;
  for (const double eps : {1e-3, 1e-4, 1e-5}) {
    const double fd = (obj->energy(u + eps * d) - obj->energy(u - eps * d)) / (2 * eps);
    const double err = std::abs(fd - slope);
    INFO("eps " << eps << " fd " << fd << " analytic " << slope);
    CHECK(err < 1e-4 * std::abs(slope) + 1e-12);
    CHECK(err <= prev_err);
    prev_err = err;
  }
}

TEST_CASE("implicit shell: a cantilever stepped at 1/24 s settles to the static deflection",
          "[implicit]") {
  Scene s = cantilever_scene();
  s = implicit(s, 1.0 / 24, 1e-6);
  Solver solver(s);
  int steps = 0, retries = 0;
  for (int f = 1; f <= 24; ++f) {
    const FrameStats fs = solver.advance_to(f / 24.0);
    steps += fs.substeps;
    retries += fs.implicit_stats.retries;
    CHECK(fs.implicit_stats.steps == fs.substeps);
  }
  CHECK(steps == 24);  // one step per frame: motion, not stiffness, bounds the step
  CHECK(retries == 0);
  const double implicit_sag = max_sag(*solver.shells()[0]);
  Solver reference(s);
  const StaticSolveResult r = reference.shells()[0]->settle(s.shot.gravity, 0.0, 1e-9, 2000, true);
  REQUIRE(r.converged);
  const double static_sag = max_sag(*reference.shells()[0]);
  INFO("implicit " << implicit_sag << " m, static " << static_sag << " m");
  CHECK(static_sag > 5e-3);  // 5.9 mm from beam theory
  CHECK(implicit_sag == Approx(static_sag).epsilon(0.01));
}

TEST_CASE("implicit shell: block Jacobi moves a stiff sheet as the factorised preconditioner does",
          "[implicit]") {
  // A 0.5 mm steel strip (the cantilever's shape) at 1/240 s steps: block Jacobi misses
  // its low bending modes by orders of magnitude, so P^-1 g is below the tolerance at rest
  // while the Newton step is not. It once "converged" with 0 iterations and the sheet
  // never moved; both preconditioners must give the same motion.
  auto run = [](ImplicitPreconditioner pre) {
    Scene s = cantilever_scene();
    const std::string name = s.shell_materials[0].name;
    s.shell_materials[0] = test::steel_sheet_material();
    s.shell_materials[0].name = name;
    s = implicit(s, 1.0 / 240);
    s.shot.implicit_preconditioner = pre;
    Solver solver(s);
    int newton = 0;
    for (int f = 1; f <= 2; ++f)
      newton += solver.advance_to(f / 24.0).implicit_stats.newton_iterations;
    return std::make_pair(max_sag(*solver.shells()[0]), newton);
  };
  const auto [fact, n_fact] = run(ImplicitPreconditioner::Factorised);
  const auto [bj, n_bj] = run(ImplicitPreconditioner::BlockJacobi);
  INFO("factorised " << fact << " m (" << n_fact << " Newton), block Jacobi " << bj << " m ("
                     << n_bj << ")");
  CHECK(fact > 1e-3);  // it swings about its static sag (3.4 mm): 2.1 mm at t = 1/12 s
  CHECK(n_bj > 0);
  CHECK(bj == Approx(fact).epsilon(1e-3));
}

TEST_CASE("implicit shell: stable at a step where the explicit integrator diverges", "[implicit]") {
  Scene s = cantilever_scene();
  const double dt = 1.0 / 24;
  {
    // Explicit at the same step: the energy explodes.
    Solver ex(s);
    ShellObject& sh = *ex.shells()[0];
    std::vector<Vec3> f;
    const double e0 = total_energy(sh, s.shot.gravity);
    for (int k = 0; k < 5; ++k) {
      sh.forces(s.shot.gravity, f, true);
      sh.integrate(f, k * dt, dt, true);
    }
    const double e1 = total_energy(sh, s.shot.gravity);
    CHECK(!(std::abs(e1) < 1e3 * std::abs(e0) + 1.0));
  }
  s = implicit(s, dt, 1e-8);  // a loose solve adds its own error to the energy
  Solver im(s);
  ShellObject& sh = *im.shells()[0];
  double e_prev = total_energy(sh, s.shot.gravity);
  // Backward Euler dissipates; it never adds energy (up to the float rounding of the
  // stored positions, far below this margin: 1e-6 of the static energy).
  const double margin = 2e-10;
  double e_first = 0;
  for (int f = 1; f <= 12; ++f) {
    im.advance_to(f * dt);
    const double e = total_energy(sh, s.shot.gravity);
    CHECK(std::isfinite(e));
    CHECK(e <= e_prev + margin);
    if (f == 1) e_first = e;
    e_prev = e;
  }
  CHECK(e_first < -1e-5);  // it sagged: gravity's work went into bending and was damped
}

TEST_CASE("implicit shell: at small steps it follows the explicit cloth swing", "[implicit]") {
  Scene s = cloth_scene();
  Solver ex(s);
  const double t_end = 0.25;
  ex.advance_to(t_end);
  s = implicit(s, 1e-3, 1e-6);
  Solver im(s);
  im.advance_to(t_end);
  const ShellObject& a = *ex.shells()[0];
  const ShellObject& b = *im.shells()[0];
  double diff = 0, moved = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = std::max(diff, static_cast<double>((a.x[i] - b.x[i]).norm()));
    moved = std::max(moved, (a.x[i].cast<double>() - a.rest[i]).norm());
  }
  INFO("largest difference " << diff << " m of a largest displacement " << moved << " m");
  CHECK(moved > 0.05);
  CHECK(diff < 0.03 * moved);
}

TEST_CASE("implicit shell: momentum is conserved and energy does not grow without loads",
          "[implicit]") {
  Scene s = cloth_scene();
  s.shells[0].pins.clear();
  s.shot.gravity = Vec3d::Zero();
  s = implicit(s, 1.0 / 24, 1e-9);
  Solver solver(s);
  ShellObject& sh = *solver.shells()[0];
  // Translation, spin and a stretch: internal forces change the shape, not the momentum.
  for (std::size_t i = 0; i < sh.size(); ++i) {
    const Vec3d r = sh.x[i].cast<double>();
    const Vec3d v = Vec3d(0.2, 0.1, -0.05) + Vec3d(0, 2.0, 0).cross(r) + 0.5 * Vec3d(r.x(), 0, 0);
    sh.v[i] = v.cast<Real>();
  }
  auto momentum = [&] {
    Vec3d p = Vec3d::Zero();
    for (std::size_t i = 0; i < sh.size(); ++i)
      p += static_cast<double>(sh.mass[i]) * sh.v[i].cast<double>();
    return p;
  };
  const Vec3d p0 = momentum();
  double e_prev = total_energy(sh, s.shot.gravity);
  double mass = 0;
  for (Real m : sh.mass) mass += static_cast<double>(m);
  for (int f = 1; f <= 6; ++f) {
    solver.advance_to(f / 24.0);
    const Vec3d p = momentum();
    INFO("frame " << f);
    CHECK((p - p0).norm() < 1e-5 * mass);
    const double e = total_energy(sh, s.shot.gravity);
    CHECK(e <= e_prev * (1 + 1e-6) + 1e-12);
    e_prev = e;
  }
}

TEST_CASE("implicit shell: the same bits with and without threads, and from a restored state",
          "[implicit]") {
  const Scene s = implicit(cloth_scene(), 1.0 / 96);
  SolverOptions serial;
  serial.serial = true;
  Solver a(s, serial), b(s);
  for (int f = 1; f <= 3; ++f) {
    a.advance_to(f / 24.0);
    b.advance_to(f / 24.0);
  }
  const ShellObject& sa = *a.shells()[0];
  const ShellObject& sb = *b.shells()[0];
  for (std::size_t i = 0; i < sa.size(); ++i) {
    REQUIRE(sa.x[i] == sb.x[i]);
    REQUIRE(sa.v[i] == sb.v[i]);
  }
  // A resume restores x, v and the time (the implicit path keeps no other state).
  Solver c(s);
  ShellObject& sc = *c.shells()[0];
  sc.x = sa.x;
  sc.v = sa.v;
  c.set_time(a.time());
  a.advance_to(4 / 24.0);
  c.advance_to(4 / 24.0);
  for (std::size_t i = 0; i < sa.size(); ++i) REQUIRE(sa.x[i] == sc.x[i]);
}

TEST_CASE("implicit shell: theta 1/2 is second order in time and keeps the energy", "[implicit]") {
  // The cantilever released flat under gravity swings about its static shape (first
  // mode about 8 Hz). Errors against a fine trapezoidal run halve with the step for
  // backward Euler and fall four times for theta 1/2.
  const double t_end = 0.1;
  auto run = [&](double theta, double dt) {
    Scene s = implicit(cantilever_scene(), dt, 1e-9);
    s.shot.implicit_theta = theta;
    Solver solver(s);
    solver.advance_to(t_end);
    return solver.shells()[0]->x;
  };
  const std::vector<Vec3> ref = run(0.5, t_end / 256);
  auto error = [&](const std::vector<Vec3>& x) {
    double e = 0;
    for (std::size_t i = 0; i < x.size(); ++i)
      e = std::max(e, static_cast<double>((x[i] - ref[i]).norm()));
    return e;
  };
  const double be1 = error(run(1.0, t_end / 16)), be2 = error(run(1.0, t_end / 32));
  const double tr1 = error(run(0.5, t_end / 16)), tr2 = error(run(0.5, t_end / 32));
  INFO("backward Euler " << be1 << " " << be2 << ", theta 1/2 " << tr1 << " " << tr2);
  CHECK(be1 / be2 > 1.6);
  CHECK(be1 / be2 < 2.6);
  CHECK(tr1 / tr2 > 3.2);
  CHECK(tr2 < 0.2 * be2);

  // Over four periods at 1/240 s (30 steps a period) backward Euler takes most of the
  // swing's energy out; theta 1/2 keeps it.
  auto swing = [&](double theta) {
    Scene s = implicit(cantilever_scene(), 1.0 / 240, 1e-9);
    s.shot.implicit_theta = theta;
    Solver solver(s);
    ShellObject& sh = *solver.shells()[0];
    const double e0 = total_energy(sh, s.shot.gravity);
    sh.settle(s.shot.gravity, 0.0, 1e-12, 4000, false);
    const double e_static = total_energy(sh, s.shot.gravity);
    Solver again(s);
    again.advance_to(0.5);
    // The share of the swing's energy (above the static state) that is left.
    return (total_energy(*again.shells()[0], s.shot.gravity) - e_static) / (e0 - e_static);
  };
  const double kept_be = swing(1.0), kept_tr = swing(0.5);
  INFO("swing energy kept: backward Euler " << kept_be << ", theta 1/2 " << kept_tr);
  CHECK(kept_be < 0.5);
  CHECK(kept_tr > 0.98);
  CHECK(kept_tr < 1.01);
}

namespace {

/// scenes/steel_dent.yaml without contact (the control points meet the ball through the
/// collider projection and penalty) over one 24 fps frame, the ball gone after 6 ms, then
/// the sheet's permanent dent: the static shape of its plastic state [m].
double direct_steel_dent(Integrator integrator, int& steps) {
  Scene s = read_scene(std::string(SHELLMPM_SOURCE_DIR) + "/scenes/steel_dent.yaml");
  s.shells[0].contact = ShellDesc::Contact::Off;
  s.shot.fps = 24;
  s.shot.dt_min = 1e-8;
  if (integrator == Integrator::Implicit) {
    s.shot.integrator = integrator;
    s.shot.dt_max = 1.0 / 24;
    s.shot.cfl = 0.125;  // steps of 0.25 ms while the ball moves at 10 m/s
  }
  Solver solver(s);
  const FrameStats fs = solver.advance_to(1.0 / 24);
  CHECK(!fs.integrity.failed());
  CHECK(fs.integrity.max_collider_depth < 1e-4);
  steps = fs.substeps;
  ShellObject& sh = *solver.shells()[0];
  CHECK(sh.settle(Vec3d::Zero(), solver.time(), 1e-6, 2000, false).converged);
  double low = 1e9;
  for (const Vec3& x : sh.x) low = std::min(low, static_cast<double>(x.y()));
  return 0.1 - low;
}

}  // namespace

TEST_CASE(
    "implicit shell: the steel sheet struck by a ball at 10 m/s dents as the explicit run, "
    "within 5%",
    "[implicit][slow]") {
  int ne = 0, ni = 0;
  const double e = direct_steel_dent(Integrator::Explicit, ne);
  const double i = direct_steel_dent(Integrator::Implicit, ni);
  INFO("permanent dent: explicit " << e << " m in " << ne << " steps, implicit " << i << " m in "
                                   << ni << " steps");
  CHECK(e > 0.01);  // a good part of the 3 cm press stays
  CHECK(std::abs(i - e) < 0.05 * e);
  CHECK(ni * 1000 < ne);
}

TEST_CASE("implicit shell: a stiffness kept between steps gives the steps a fresh one gives",
          "[implicit]") {
  // The cantilever released flat: two steps in one epoch (the second reuses the first's
  // stiffness) against two steps in separate epochs (each assembles its own).
  const Scene s = cantilever_scene();
  Solver a(s), b(s);
  ShellObject& sa = *a.shells()[0];
  ShellObject& sb = *b.shells()[0];
  ShellImplicitStep kept(sa), fresh(sb);
  NewtonOptions opt;
  opt.tolerance = 1e-9;
  opt.refresh_after = 2;
  const double dt = 1.0 / 240;
  for (int k = 0; k < 2; ++k) {
    REQUIRE(kept.step(sa, s.shot.gravity, k * dt, dt, 1.0, opt, ImplicitPreconditioner::Factorised,
                      true, nullptr, 1)
                .converged);
    REQUIRE(fresh
                .step(sb, s.shot.gravity, k * dt, dt, 1.0, opt, ImplicitPreconditioner::Factorised,
                      true, nullptr, 1 + k)
                .converged);
  }
  CHECK(kept.reused_steps() == 1);
  CHECK(fresh.reused_steps() == 0);
  double diff = 0, moved = 0;
  for (std::size_t i = 0; i < sa.size(); ++i) {
    diff = std::max(diff, static_cast<double>((sa.x[i] - sb.x[i]).norm()));
    moved = std::max(moved, (sa.x[i].cast<double>() - sa.rest[i]).norm());
  }
  INFO("largest difference " << diff << " m of a largest displacement " << moved << " m");
  CHECK(moved > 1e-5);
  CHECK(diff < 1e-4 * moved);
}

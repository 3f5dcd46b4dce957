// The static solver (sim/shell/static_solver.h) on a spring chain with a known answer,
// with and without the finite-difference stiffness, and the shell pre-roll built on it.
#include <catch2/catch.hpp>
#include <cmath>

#include "sim/shell/static_solver.h"
#include "sim/solver/solver.h"
#include "tests/support/shell_fixtures.h"

using namespace shellmpm;

namespace {

/// n springs of stiffness k along x; point 0 pinned, force F on the last point.
/// Equilibrium: every spring carries F, so point i moves by i F / k.
struct Chain {
  int n = 40;
  double k = 50.0;
  Vec3d F{0.3, -0.2, 0.1};
  std::vector<Vec3d> rest;
  std::vector<std::uint8_t> free_mask;
  int calls = 0;
  Chain() {
    for (int i = 0; i <= n; ++i) rest.emplace_back(0.1 * i, 0, 0);
    free_mask.assign(n + 1, 7);
    free_mask[0] = 0;
  }
  void forces(const std::vector<Vec3d>& p, std::vector<Vec3d>& f) {
    ++calls;
    for (int i = 0; i < n; ++i) {
      const Vec3d s = k * ((p[i + 1] - p[i]) - (rest[i + 1] - rest[i]));
      f[i] += s;
      f[i + 1] -= s;
    }
    f[n] += F;
  }
  void check(const std::vector<Vec3d>& x) const {
    for (int i = 0; i <= n; ++i) {
      const Vec3d u = x[i] - rest[i];
      REQUIRE((u - i * F / k).norm() < 1e-6 * (n * F.norm() / k));
    }
    REQUIRE(x[0] == rest[0]);  // pinned
  }
};

Scene drape_scene(PrerollSettings::Method method) {
  Scene s;
  s.path = "test";
  s.shot.dx = 0.05;
  s.shot.cfl = 0.5;
  s.shot.dt_max = 1e-2;
  s.shot.domain_min = Vec3d(-5, -5, -5);
  s.shot.domain_max = Vec3d(5, 5, 5);
  ShellMaterialDesc m = test::cloth_material();
  s.shell_materials.push_back(m);
  ShellDesc sh;
  sh.name = "drape";
  sh.kind = ShellDesc::Kind::Sheet;
  sh.resolution[0] = sh.resolution[1] = 8;
  PinDesc pin;
  pin.indices = {0, 8, 72, 80};
  sh.pins.push_back(pin);
  sh.point_loads.push_back({40, Vec3d(0.01, -0.05, 0.02), ""});
  s.shells.push_back(sh);
  s.preroll.enabled = true;
  s.preroll.method = method;
  return s;
}

}  // namespace

TEST_CASE("L-BFGS static solve: a pinned spring chain under an end load", "[static]") {
  Chain c;
  auto forces = [&](const std::vector<Vec3d>& p, std::vector<Vec3d>& f) { c.forces(p, f); };
  StaticSolveOptions opt;
  opt.tolerance = 1e-9;
  opt.max_iterations = 4000;
  std::vector<Vec3d> x = c.rest;
  const StaticSolveResult r = solve_static(x, c.free_mask, forces, opt);
  INFO("iterations " << r.iterations << " residual " << r.residual << " force calls " << c.calls);
  REQUIRE(r.converged);
  REQUIRE(r.residual < 1e-9);
  REQUIRE(r.hessian_evaluations == 0);
  REQUIRE(r.force_evaluations == c.calls);
  c.check(x);
  // An unmet tolerance is reported, not hidden.
  std::vector<Vec3d> y = c.rest;
  opt.tolerance = 1e-30;
  opt.max_iterations = 3;
  const StaticSolveResult r2 = solve_static(y, c.free_mask, forces, opt);
  REQUIRE_FALSE(r2.converged);
  REQUIRE(r2.iterations <= 3);
  // No equilibrium (nothing pinned, a constant load): stops as stalled, not converged.
  std::vector<Vec3d> z = c.rest;
  std::vector<std::uint8_t> all_free(z.size(), 7);
  opt.tolerance = 1e-9;
  opt.max_iterations = 100000;
  opt.stall_iterations = 50;
  const StaticSolveResult r3 = solve_static(z, all_free, forces, opt);
  REQUIRE_FALSE(r3.converged);
  REQUIRE(r3.stalled);
  REQUIRE(r3.iterations < 1000);
}

TEST_CASE("static solve with a finite-difference stiffness: Newton on a linear chain", "[static]") {
  Chain c;
  auto forces = [&](const std::vector<Vec3d>& p, std::vector<Vec3d>& f) { c.forces(p, f); };
  StaticSolveOptions opt;
  opt.tolerance = 1e-9;
  opt.max_iterations = 100;
  opt.coupling.resize(c.n + 1);
  for (int i = 0; i <= c.n; ++i)
    for (int j = std::max(0, i - 1); j <= std::min(c.n, i + 1); ++j) opt.coupling[i].push_back(j);
  std::vector<Vec3d> x = c.rest;
  const StaticSolveResult r = solve_static(x, c.free_mask, forces, opt);
  INFO("iterations " << r.iterations << " residual " << r.residual << " force calls " << c.calls);
  REQUIRE(r.converged);
  REQUIRE(r.hessian_evaluations == 1);
  // The stiffness of a linear problem is exact up to round-off: Newton converges at once
  // (plain L-BFGS above needs about n iterations).
  REQUIRE(r.iterations <= 3);
  // A distance-2 colouring of a chain needs 3 colours: 3 x 3 perturbed evaluations.
  REQUIRE(c.calls < 20);
  c.check(x);
}

TEST_CASE("static solve halves steps into non-finite forces", "[static]") {
  // One point on a spring to the origin, pulled by F, with forces undefined (NaN) beyond
  // |x| > 1.5: the first full step (to x = 2) lands outside and must be cut back.
  const double k = 1.0, F = 2.0;
  auto forces = [&](const std::vector<Vec3d>& p, std::vector<Vec3d>& f) {
    const double u = p[0].x();
    f[0].x() += std::abs(u) > 1.5 ? std::nan("") : -k * u + F * (1 - u * u / 4);
  };
  StaticSolveOptions opt;
  opt.tolerance = 1e-10;
  opt.max_iterations = 200;
  opt.max_move = 10;     // no trust cap: the line search alone must cope
  opt.coupling = {{0}};  // Newton: the first step goes to u = 2
  std::vector<Vec3d> x{Vec3d(0, 0, 0)};
  const StaticSolveResult r = solve_static(x, {1}, forces, opt);
  REQUIRE(r.converged);
  // Root of -u + 2 (1 - u^2 / 4) = 0: u = -1 + sqrt(5).
  REQUIRE(x[0].x() == Approx(std::sqrt(5.0) - 1).epsilon(1e-8));
}

TEST_CASE("static and dynamic pre-roll reach the same drape", "[shell][static]") {
  Solver dyn(drape_scene(PrerollSettings::Method::Dynamic));
  Solver sta(drape_scene(PrerollSettings::Method::Static));
  PrerollSettings p = drape_scene(PrerollSettings::Method::Dynamic).preroll;
  p.tolerance = 1e-4;
  const int steps_dynamic = dyn.preroll(p);
  p.method = PrerollSettings::Method::Static;
  const int iterations_static = sta.preroll(p);
  const ShellObject& a = *dyn.shells()[0];
  const ShellObject& b = *sta.shells()[0];
  double diff = 0, sag = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = std::max(diff, static_cast<double>((a.x[i] - b.x[i]).norm()));
    sag = std::max(sag, static_cast<double>(b.rest[i].y() - b.x[i].y()));
    REQUIRE(b.v[i].norm() == 0);
  }
  INFO("dynamic steps " << steps_dynamic << " static iterations " << iterations_static
                        << " max difference " << diff << " sag " << sag);
  REQUIRE(sag > 0.05);
  REQUIRE(diff < 1e-2 * sag);
  // Pins stay where they are.
  for (int i : {0, 8, 72, 80}) REQUIRE((b.x[i].cast<double>() - b.rest[i]).norm() == 0);
  // An unreachable tolerance is an error that names the shell.
  Solver bad(drape_scene(PrerollSettings::Method::Static));
  p.tolerance = 1e-30;
  p.max_steps = 2;
  REQUIRE_THROWS_WITH(bad.preroll(p), Catch::Contains("'drape'") && Catch::Contains("max_steps"));
  // No pins: no equilibrium under gravity; the solve stops for lack of progress.
  Scene free_fall = drape_scene(PrerollSettings::Method::Static);
  free_fall.shells[0].pins.clear();
  Solver none(free_fall);
  p.tolerance = 1e-4;
  p.max_steps = 100000;
  REQUIRE_THROWS_WITH(none.preroll(p), Catch::Contains("no progress"));
}

#include <catch2/catch.hpp>

#include "sim/shell/static_solver.h"

using namespace shellmpm;

TEST_CASE("L-BFGS static solve: a pinned spring chain under an end load", "[static]") {
  // n springs of stiffness k along x; point 0 pinned, force F on the last point.
  // Equilibrium: every spring carries F, so point i moves by i F / k.
  const int n = 40;
  const double k = 50.0;
  const Vec3d F(0.3, -0.2, 0.1);
  std::vector<Vec3> x(n + 1);
  for (int i = 0; i <= n; ++i) x[i] = Vec3(Real(i) * Real(0.1), 0, 0);
  const std::vector<Vec3> rest = x;
  std::vector<std::uint8_t> free_mask(n + 1, 7);
  free_mask[0] = 0;
  int calls = 0;
  auto forces = [&](const std::vector<Vec3>& p, std::vector<Vec3>& f) {
    ++calls;
    for (int i = 0; i < n; ++i) {
      const Vec3 s = Real(k) * ((p[i + 1] - p[i]) - (rest[i + 1] - rest[i]));
      f[i] += s;
      f[i + 1] -= s;
    }
    f[n] += F.cast<Real>();
  };
  const StaticSolveResult r = solve_static(x, free_mask, forces, 1e-4, 2000);
  INFO("iterations " << r.iterations << " residual " << r.residual << " force calls " << calls);
  REQUIRE(r.converged);
  REQUIRE(r.residual < 1e-4);
  for (int i = 0; i <= n; ++i) {
    const Vec3d u = (x[i] - rest[i]).cast<double>();
    REQUIRE((u - i * F / k).norm() < 1e-3 * (n * F.norm() / k));
  }
  REQUIRE(x[0] == rest[0]);  // pinned
  // An unmet tolerance is reported, not hidden.
  std::vector<Vec3> y = rest;
  const StaticSolveResult r2 = solve_static(y, free_mask, forces, 1e-30, 3);
  REQUIRE_FALSE(r2.converged);
  REQUIRE(r2.iterations <= 3);
}

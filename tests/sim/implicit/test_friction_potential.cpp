// Coulomb friction as a lagged potential (sim/implicit/friction_potential.h): its gradient
// and Hessian against finite differences in both regimes, the Coulomb bound, no normal
// part, and convexity.
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>
#include <cmath>

#include "sim/implicit/friction_potential.h"

using namespace shellmpm;

namespace {
LaggedFriction plate() {
  LaggedFriction f;
  f.n = Vec3d(0.3, 0.9, -0.1).normalized();
  f.vc = Vec3d(0.05, -0.3, 0.02);
  f.bound = 2e-4;
  f.eps = 1e-3;
  return f;
}

/// u with tangential speed s relative to the surface and some normal velocity.
Vec3d at_speed(const LaggedFriction& f, double s) {
  const Vec3d t = (Vec3d(1, 0.2, 0.4) - Vec3d(1, 0.2, 0.4).dot(f.n) * f.n).normalized();
  return f.vc + s * t + 0.7 * f.n;
}
}  // namespace

TEST_CASE(
    "friction potential: gradient and Hessian match finite differences, sticking and "
    "sliding",
    "[implicit]") {
  const LaggedFriction f = plate();
  for (const double s : {0.0, 2e-4, 7e-4, 3e-3, 0.4}) {
    INFO("tangential speed " << s);
    const Vec3d u = at_speed(f, s) + Vec3d(1e-5, -2e-5, 3e-5) * (s > 0 ? 1 : 0);
    const double h = 1e-7;
    const Vec3d g = f.gradient(u);
    const Mat3d H = f.hessian(u);
    for (int a = 0; a < 3; ++a) {
      Vec3d e = Vec3d::Zero();
      e[a] = h;
      const double dE = (f.energy(u + e) - f.energy(u - e)) / (2 * h);
      CHECK(g[a] == Approx(dE).margin(1e-6 * f.bound));
      const Vec3d dg = (f.gradient(u + e) - f.gradient(u - e)) / (2 * h);
      for (int b = 0; b < 3; ++b)
        CHECK(H(b, a) == Approx(dg[b]).epsilon(1e-4).margin(1e-4 * f.bound / f.eps));
    }
    // Symmetric, positive semi-definite, and blind to the normal velocity.
    CHECK((H - H.transpose()).norm() < 1e-12 * H.norm() + 1e-30);
    const Eigen::SelfAdjointEigenSolver<Mat3d> es(H);
    CHECK(es.eigenvalues().minCoeff() > -1e-9 * f.bound / f.eps);
    CHECK(std::abs(g.dot(f.n)) < 1e-12);
    CHECK((H * f.n).norm() < 1e-9 * f.bound / f.eps);
  }
}

TEST_CASE(
    "friction potential: the full Coulomb impulse against sliding, a stiff spring when "
    "sticking",
    "[implicit]") {
  const LaggedFriction f = plate();
  // Sliding faster than eps: the friction impulse has the bound's size, against v_t.
  const Vec3d u = at_speed(f, 0.05);
  const Vec3d g = f.gradient(u);
  CHECK(g.norm() == Approx(f.bound).epsilon(1e-12));
  CHECK(g.dot(f.tangential(u)) > 0);  // dD/du along v_t: the impulse -g opposes it
  // Below eps the impulse grows from zero, with curvature 2 bound / eps at rest.
  CHECK(f.gradient(at_speed(f, 0)).norm() < 1e-12 * f.bound);
  CHECK(f.gradient(at_speed(f, 0.5 * f.eps)).norm() < f.bound);
  const Mat3d H0 = f.hessian(at_speed(f, 0));
  const Vec3d t = f.tangential(at_speed(f, 1.0));
  CHECK(t.normalized().dot(H0 * t.normalized()) == Approx(2 * f.bound / f.eps));
  // D is continuous across eps and never less than bound * |v_t|'s smoothing below it.
  CHECK(f.energy(at_speed(f, f.eps * (1 - 1e-9))) ==
        Approx(f.energy(at_speed(f, f.eps * (1 + 1e-9)))).epsilon(1e-6));
  CHECK(f.energy(at_speed(f, 0.3)) == Approx(f.bound * 0.3).epsilon(1e-12));
}

// The Newton-PCG minimiser (sim/implicit/newton.h) on objectives with known minima.
#include <catch2/catch.hpp>
#include <cmath>

#include "sim/implicit/newton.h"

using namespace shellmpm;

namespace {

/// E(u) = sum_i a_i (u_i - c_i)^4 / 4 + b_i (u_i - c_i)^2 / 2 + coupling k (u_i - u_i+1)^2 / 2,
/// entries in `fixed` held. Convex; the minimum is c where nothing is held.
class Quartic final : public ImplicitObjective {
 public:
  explicit Quartic(int n) : a(n), b(n), c(n), fixed(n, 0) {
    for (int i = 0; i < n; ++i) {
      a[i] = 1.0 + i % 3;
      b[i] = 1e-3 * (1 + i % 5);
      c[i] = std::sin(1.0 + i);
    }
  }
  Eigen::Index size() const override { return a.size(); }
  double energy(const VecXd& u) override {
    double e = 0;
    for (Eigen::Index i = 0; i < u.size(); ++i) {
      const double d = u[i] - c[i];
      e += a[i] * std::pow(d, 4) / 4 + b[i] * d * d / 2;
      if (i + 1 < u.size()) e += k * std::pow(u[i] - u[i + 1] - (c[i] - c[i + 1]), 2) / 2;
    }
    return e;
  }
  void gradient(const VecXd& u, VecXd& g) override {
    g.setZero(u.size());
    for (Eigen::Index i = 0; i < u.size(); ++i) {
      const double d = u[i] - c[i];
      g[i] += a[i] * d * d * d + b[i] * d;
      if (i + 1 < u.size()) {
        const double s = k * (u[i] - u[i + 1] - (c[i] - c[i + 1]));
        g[i] += s;
        g[i + 1] -= s;
      }
    }
    project(g);
  }
  void project(VecXd& d) const override {
    for (Eigen::Index i = 0; i < d.size(); ++i)
      if (fixed[i]) d[i] = 0;
  }
  VecXd a, b, c;
  std::vector<char> fixed;
  double k = 5.0;
};

}  // namespace

TEST_CASE("newton: converges to the minimum, the objective falls at every iteration",
          "[implicit]") {
  Quartic q(40);
  VecXd u = VecXd::Zero(40);
  NewtonOptions opt;
  opt.tolerance = 1e-10;
  opt.max_iterations = 100;
  const NewtonReport rep = newton_minimise(q, u, opt);
  REQUIRE(rep.converged);
  CHECK(rep.iterations > 2);  // nonlinear: more than one Newton step
  CHECK((u - q.c).lpNorm<Eigen::Infinity>() < 1e-3);
  for (std::size_t i = 1; i < rep.energies.size(); ++i)
    CHECK(rep.energies[i] < rep.energies[i - 1]);
}

TEST_CASE("newton: held entries keep their value", "[implicit]") {
  Quartic q(20);
  q.fixed[0] = q.fixed[7] = 1;
  VecXd u = VecXd::Zero(20);
  u[7] = 0.25;
  NewtonOptions opt;
  opt.tolerance = 1e-9;
  opt.max_iterations = 100;
  const NewtonReport rep = newton_minimise(q, u, opt);
  REQUIRE(rep.converged);
  CHECK(u[0] == 0.0);
  CHECK(u[7] == 0.25);
  VecXd g;
  q.gradient(u, g);
  CHECK(g.lpNorm<Eigen::Infinity>() <= 1e-9);
}

TEST_CASE("newton: an iteration cap below what is needed reports no convergence", "[implicit]") {
  Quartic q(20);
  VecXd u = VecXd::Zero(20);
  NewtonOptions opt;
  opt.tolerance = 1e-12;
  opt.max_iterations = 1;
  const NewtonReport rep = newton_minimise(q, u, opt);
  CHECK_FALSE(rep.converged);
  CHECK(rep.iterations == 1);
  CHECK(rep.residual > opt.tolerance);
}

TEST_CASE("newton: the default Hessian product matches the analytic one", "[implicit]") {
  Quartic q(12);
  VecXd u(12), d(12), hd;
  for (int i = 0; i < 12; ++i) {
    u[i] = 0.3 * std::cos(i);
    d[i] = std::sin(2.0 * i);
  }
  q.hessian_product(u, d, hd);
  for (int i = 0; i < 12; ++i) {
    double h = (3 * q.a[i] * std::pow(u[i] - q.c[i], 2) + q.b[i]) * d[i];
    if (i > 0) h += q.k * (d[i] - d[i - 1]);
    if (i + 1 < 12) h += q.k * (d[i] - d[i + 1]);
    CHECK(hd[i] == Approx(h).epsilon(1e-6).margin(1e-9));
  }
}

TEST_CASE("newton: refresh_after rebuilds the preconditioner during a long solve", "[implicit]") {
  // The quartic with a diagonal preconditioner, the inverse of H's diagonal where it was
  // built: far from the minimum it is stale, and the refresh counts.
  class Refreshed final : public ImplicitObjective {
   public:
    explicit Refreshed(int n) : q(n), diag(VecXd::Ones(n)) {}
    Eigen::Index size() const override { return q.size(); }
    double energy(const VecXd& u) override { return q.energy(u); }
    void gradient(const VecXd& u, VecXd& g) override { q.gradient(u, g); }
    void project(VecXd& d) const override { q.project(d); }
    void prepare_preconditioner(const VecXd& u) override {
      ++builds;
      for (Eigen::Index i = 0; i < u.size(); ++i) {
        const double d = u[i] - q.c[i];
        diag[i] = 3 * q.a[i] * d * d + q.b[i] + 2 * q.k;
      }
    }
    void apply_preconditioner(const VecXd& r, VecXd& z) const override {
      z = r.cwiseQuotient(diag);
    }
    Quartic q;
    VecXd diag;
    int builds = 0;
  };
  for (int every : {0, 3}) {
    CAPTURE(every);
    Refreshed obj(30);
    VecXd u = VecXd::Constant(30, 2.0);
    NewtonOptions opt;
    opt.tolerance = 1e-10;
    opt.max_iterations = 100;
    opt.refresh_after = every;
    const NewtonReport rep = newton_minimise(obj, u, opt);
    REQUIRE(rep.converged);
    CHECK((u - obj.q.c).lpNorm<Eigen::Infinity>() < 1e-3);
    REQUIRE(rep.iterations > 3);
    // Built once at the start, then at every multiple of `every` iterations reached before
    // convergence (the last check may come after the final iteration).
    const int expected_min = every ? 1 + (rep.iterations - 1) / every : 1;
    CHECK(obj.builds >= expected_min);
    CHECK(obj.builds <= (every ? 1 + rep.iterations / every : 1));
  }
}

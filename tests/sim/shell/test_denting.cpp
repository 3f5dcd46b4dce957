// Tests for denting (supplement sec. 7): the slope +-1 return mapping, the per-layer
// plastic update, and permanent dents of a Kirchhoff-Love shell.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include "sim/core/parallel.h"
#include "sim/shell/denting.h"
#include "sim/shell/kirchhoff_love.h"
#include "sim/shell/shell_quadrature.h"
#include "tests/support/bezier_test_basis.h"

namespace {

using namespace shellmpm_test;

using Shell = shellmpm::KirchhoffLoveShellT<double>;
using V3 = Eigen::Vector3d;
using V2 = Eigen::Vector2d;

constexpr double kMu = 3.0e5, kLambda = 2.0e5, kYield = 1.0e3;

shellmpm::ShellMaterialDesc dent_material(double yield) {
  shellmpm::ShellMaterialDesc m;
  m.youngs_modulus = 1e6;
  m.poisson_ratio = 0.3;
  m.density = 1000;
  m.thickness = 0.01;
  m.yield_stress = yield;
  return m;
}

V3 cylinder(const V2& uv, double kappa) {
  if (kappa == 0) return V3(uv.x(), uv.y(), 0);
  const double R = 1 / kappa;
  return V3(R * std::sin(uv.x() / R), uv.y(), R * (1 - std::cos(uv.x() / R)));
}

std::vector<V3> bent(const BezierShell& s, double kappa) {
  return interpolate(s, [kappa](const V2& uv) { return cylinder(uv, kappa); });
}

double energy_of(const Shell& sh, const std::vector<V3>& x) {
  return sh.energy(x.data(), nullptr).total;
}

// Forces vs. central differences along random directions; the error must fall as eps^2.
void check_fd(const Shell& sh, const std::vector<V3>& x, std::mt19937& rng) {
  std::normal_distribution<double> nd(0.0, 1.0);
  std::vector<V3> f(x.size(), V3::Zero());
  sh.energy(x.data(), f.data());
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<V3> dir(x.size());
    for (V3& d : dir) d = V3(nd(rng), nd(rng), nd(rng));
    double a = 0;
    for (std::size_t i = 0; i < x.size(); ++i) a -= f[i].dot(dir[i]);
    auto err = [&](double eps) {
      std::vector<V3> xp = x, xm = x;
      for (std::size_t i = 0; i < x.size(); ++i) {
        xp[i] += eps * dir[i];
        xm[i] -= eps * dir[i];
      }
      return std::abs((energy_of(sh, xp) - energy_of(sh, xm)) / (2 * eps) - a);
    };
    const double e4 = err(1e-4), e5 = err(1e-5);
    INFO("analytic " << a << " err(1e-4) " << e4 << " err(1e-5) " << e5);
    CHECK(std::abs(a) > 0);
    CHECK((e5 < 0.05 * e4 || e5 < 1e-9 * std::abs(a)));
    CHECK(e4 < 1e-3 * std::abs(a));
  }
}

}  // namespace

TEST_CASE("denting return map: feasible states untouched, others onto the boundary", "[denting]") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.006, 0.006);
  int projected = 0, kept = 0;
  for (int i = 0; i < 2000; ++i) {
    const V2 l0(u(rng), u(rng));
    V2 l = l0;
    const V2 tau0 = shellmpm::denting_principal_stress(kMu, kLambda, l0);
    const double f0 = shellmpm::denting_yield_function(tau0(0), tau0(1), kYield);
    const bool yielded = shellmpm::denting_return_map(kMu, kLambda, kYield, l);
    CHECK(yielded == (f0 > 0));
    if (!yielded) {
      ++kept;
      CHECK(l(0) == l0(0));  // bitwise
      CHECK(l(1) == l0(1));
      continue;
    }
    ++projected;
    const V2 tau = shellmpm::denting_principal_stress(kMu, kLambda, l);
    // On the boundary of the slope +-1 region.
    CHECK(std::abs(shellmpm::denting_yield_function(tau(0), tau(1), kYield)) < 1e-12);
    // Released energy is non-negative.
    CHECK(shellmpm::denting_energy_density(kMu, kLambda, l) <=
          shellmpm::denting_energy_density(kMu, kLambda, l0));
    // Perpendicular return = closest feasible point: no sampled feasible point is closer.
    const double dist = (tau0 - tau).norm();
    for (int k = 0; k < 50; ++k) {
      const V2 other(u(rng) * 2e5, u(rng) * 2e5);
      if (shellmpm::denting_yield_function(other(0), other(1), kYield) <= 0)
        CHECK(dist <= (tau0 - other).norm() + 1e-9);
    }
    // Idempotent (a second projection moves the state by round-off at most).
    V2 again = l;
    shellmpm::denting_return_map(kMu, kLambda, kYield, again);
    CHECK((again - l).norm() < 1e-15);
  }
  CHECK(projected > 100);
  CHECK(kept > 100);
  // Uniaxial yield at sigma_y, equi-biaxial yield at sigma_y, pure shear at sigma_y/sqrt(3).
  CHECK(shellmpm::denting_yield_function(kYield, 0.0, kYield) <= 1e-15);
  CHECK(shellmpm::denting_yield_function(kYield, kYield, kYield) == Approx(0.0).margin(1e-15));
  CHECK(shellmpm::denting_yield_function(kYield / std::sqrt(3.0), -kYield / std::sqrt(3.0),
                                         kYield) == Approx(0.0).margin(1e-15));
}

TEST_CASE("denting layer projection keeps principal directions and lands on yield", "[denting]") {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 200; ++i) {
    Eigen::Matrix2d r;  // in-plane block of F
    r << 1 + 0.02 * u(rng), 0.02 * u(rng), 0.0, 1 + 0.02 * u(rng);
    Eigen::Matrix2d fp_inv;
    fp_inv << 1 + 0.003 * u(rng), 0.003 * u(rng), 0.003 * u(rng), 1 + 0.003 * u(rng);
    const Eigen::Matrix2d fp_old = fp_inv;
    const Eigen::Matrix2d re = r * fp_inv;  // trial elastic block
    const Eigen::Matrix2d Ce = re.transpose() * re;
    bool yielded = false;
    const double released =  // the plastic work
        shellmpm::denting_project_layer(kMu, kLambda, kYield, Ce, fp_inv, &yielded);
    CHECK(released >= 0);
    const Eigen::Matrix2d re_new = r * fp_inv;
    const Eigen::JacobiSVD<Eigen::Matrix2d> svd(re_new);
    const V2 l(std::log(svd.singularValues()(0)), std::log(svd.singularValues()(1)));
    const V2 tau = shellmpm::denting_principal_stress(kMu, kLambda, l);
    const double f = shellmpm::denting_yield_function(tau(0), tau(1), kYield);
    if (!yielded) {
      CHECK(released == 0);
      CHECK(fp_inv == fp_old);
      CHECK(f <= 0);
      continue;
    }
    CHECK(std::abs(f) < 1e-8);
    // Same V: the new elastic Cauchy-Green commutes with the trial one.
    const Eigen::Matrix2d Cn = re_new.transpose() * re_new;
    CHECK((Cn * Ce - Ce * Cn).norm() < 1e-12);
    // Plastic work = the returned stress times the plastic strain increment, at most the
    // elastic energy the return releases, psi(trial) - psi(projected).
    const Eigen::JacobiSVD<Eigen::Matrix2d> svd0(re);
    const V2 l0(std::log(svd0.singularValues()(0)), std::log(svd0.singularValues()(1)));
    CHECK(released == Approx(tau.dot(l0 - l)).epsilon(1e-6));
    CHECK(released <= shellmpm::denting_energy_density(kMu, kLambda, l0) -
                          shellmpm::denting_energy_density(kMu, kLambda, l) + 1e-9);
  }
}

TEST_CASE("denting: loading below yield and unloading leaves no plastic strain", "[denting]") {
  const BezierShell s = make_bezier_grid(2, 5, 6);
  const std::vector<V3> flat = bent(s, 0.0);
  Shell sh(s.points, s.weights, flat, dent_material(1.5e3), 3);
  REQUIRE(sh.has_plasticity());
  const std::vector<double> before = sh.plastic_state();
  for (double kappa : {0.05, 0.1, 0.05}) {
    const std::vector<V3> x = bent(s, kappa);
    CHECK(sh.project_plasticity(x.data()) == 0.0);
  }
  CHECK(sh.plastic_state() == before);  // bitwise
  CHECK(energy_of(sh, flat) < 1e-20);
  // Without a yield stress the call is a no-op.
  Shell elastic(s.points, s.weights, flat, dent_material(0.0), 3);
  const std::vector<V3> x = bent(s, 2.0);
  CHECK(elastic.project_plasticity(x.data()) == 0.0);
  CHECK(elastic.plastic_state().empty());
}

TEST_CASE("denting: bending beyond yield leaves a permanent curvature", "[denting]") {
  std::mt19937 rng(21);
  const BezierShell s = make_bezier_grid(2, 5, 6);
  const std::vector<V3> flat = bent(s, 0.0);
  Shell sh(s.points, s.weights, flat, dent_material(1.5e3), 3);
  const double kmax = 1.0;
  double work = 0;
  for (int step = 1; step <= 10; ++step) {  // load gradually
    const std::vector<V3> x = bent(s, kmax * step / 10.0);
    const double w = sh.project_plasticity(x.data());
    CHECK(w >= 0);
    work += w;
  }
  CHECK(work > 0);
  const std::vector<V3> loaded = bent(s, kmax);
  const double e_loaded = energy_of(sh, loaded);
  // Projected states are feasible: projecting again at the same state does nothing
  // (up to round-off of the stored state).
  const double again = sh.project_plasticity(loaded.data());
  CHECK(again <= 1e-9 * e_loaded);
  // Unloaded to the original flat state: stressed (energy > 0).
  const double e_flat = energy_of(sh, flat);
  CHECK(e_flat > 0.05 * e_loaded);
  // The stress-free curvature is nonzero: the energy along the cylinder family has its
  // minimum strictly between 0 and kmax.
  double best_k = 0, best_e = e_flat;
  for (int i = 1; i <= 40; ++i) {
    const double k = kmax * i / 40.0;
    const double e = energy_of(sh, bent(s, k));
    if (e < best_e) {
      best_e = e;
      best_k = k;
    }
  }
  INFO("stress-free curvature " << best_k << " energy there " << best_e << " flat " << e_flat);
  CHECK(best_k > 0.1 * kmax);
  CHECK(best_k < kmax);
  CHECK(best_e < 0.2 * e_flat);
  // Forces stay the exact gradient with an active plastic state.
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  for (int c = 0; c < 2; ++c) {
    std::vector<V3> x = bent(s, 0.5 * c);
    for (V3& v : x) v += V3(u(rng), u(rng), u(rng));
    check_fd(sh, x, rng);
  }
  // Checkpoint round trip is exact; reset restores the stress-free flat state.
  const std::vector<double> state = sh.plastic_state();
  Shell other(s.points, s.weights, flat, dent_material(1.5e3), 3);
  other.set_plastic_state(state);
  CHECK(energy_of(other, flat) == e_flat);
  CHECK_THROWS(other.set_plastic_state(std::vector<double>(3, 1.0)));
  other.reset_plastic_state();
  CHECK(energy_of(other, flat) < 1e-20);
}

TEST_CASE("denting projection does not depend on the thread count", "[denting]") {
  std::mt19937 rng(4);
  const BezierShell s = make_bezier_grid(8, 3, 7);  // 896 quadrature points
  const std::vector<V3> flat = bent(s, 0.0);
  Shell a(s.points, s.weights, flat, dent_material(1.5e3), 3);
  Shell b(s.points, s.weights, flat, dent_material(1.5e3), 3);
  Shell c(s.points, s.weights, flat, dent_material(1.5e3), 3);
  std::uniform_real_distribution<double> u(-0.003, 0.003);
  std::vector<V3> x = bent(s, 1.2);
  for (V3& v : x) v += V3(u(rng), u(rng), u(rng));
  const double wa = a.project_plasticity(x.data(), true);
  const double wb = b.project_plasticity(x.data(), false);
  double wc;
  {
    shellmpm::ThreadLimit one(1);
    wc = c.project_plasticity(x.data(), false);
  }
  CHECK(wa > 0);
  CHECK(wa == wb);
  CHECK(wa == wc);
  CHECK(a.plastic_state() == b.plastic_state());
  CHECK(a.plastic_state() == c.plastic_state());
}

TEST_CASE(
    "denting in the energy: its forces are the returned stress's, its energy the "
    "incremental potential's",
    "[denting]") {
  std::mt19937 rng(8);
  const BezierShell s = make_bezier_grid(2, 5, 6);
  const std::vector<V3> flat = bent(s, 0.0);
  // A plastic state from an earlier bend, then a step that bends much further (a long
  // implicit step's trial state) with some noise.
  Shell start(s.points, s.weights, flat, dent_material(1.5e3), 3);
  start.project_plasticity(bent(s, 0.3).data());
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  std::vector<V3> x = bent(s, 1.0);
  for (V3& v : x) v += V3(u(rng), u(rng), u(rng));
  auto copy = [&] {
    auto sh = std::make_unique<Shell>(s.points, s.weights, flat, dent_material(1.5e3), 3);
    sh->set_plastic_state(start.plastic_state());
    return sh;
  };
  const auto in = copy(), after = copy();
  in->set_plasticity_in_energy(true);
  REQUIRE(in->plasticity_in_energy());
  const double work = after->project_plasticity(x.data());
  REQUIRE(work > 0);

  // The forces at x with the return inside the energy are those of the state the return
  // mapping leaves at x.
  std::vector<V3> f_in(x.size(), V3::Zero()), f_after(x.size(), V3::Zero()),
      f_el(x.size(), V3::Zero());
  in->energy(x.data(), f_in.data());
  after->energy(x.data(), f_after.data());
  start.energy(x.data(), f_el.data());
  double fmax = 0, diff = 0, diff_el = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    fmax = std::max(fmax, f_after[i].norm());
    diff = std::max(diff, (f_in[i] - f_after[i]).norm());
    diff_el = std::max(diff_el, (f_el[i] - f_after[i]).norm());
  }
  INFO("largest force " << fmax << ", in the energy off by " << diff << ", elastic trial off by "
                        << diff_el);
  CHECK(diff < 1e-7 * fmax);
  CHECK(diff_el > 0.1 * fmax);  // the trial stress is far from the returned one here

  // The incremental potential is the returned elastic energy plus the return's plastic
  // work, far below the trial's elastic energy.
  const double e_in = energy_of(*in, x), e_trial = energy_of(start, x),
               e_after = energy_of(*after, x);
  INFO("trial " << e_trial << " incremental " << e_in << " returned " << e_after << " work "
                << work);
  CHECK(e_in == Approx(e_after + work).epsilon(1e-9));
  CHECK(e_in < 0.5 * e_trial);

  // Its gradient is exact (central differences along random directions; the energy is
  // only C1 where layers cross their bounds, so the steps are short), and below yield it
  // is bitwise the elastic energy.
  std::normal_distribution<double> nd(0.0, 1.0);
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<V3> dir(x.size()), xp = x, xm = x;
    double slope = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      dir[i] = V3(nd(rng), nd(rng), nd(rng));
      slope -= f_in[i].dot(dir[i]);
      xp[i] += 1e-7 * dir[i];
      xm[i] -= 1e-7 * dir[i];
    }
    const double fd = (energy_of(*in, xp) - energy_of(*in, xm)) / 2e-7;
    INFO("slope " << slope << " differences " << fd);
    CHECK(std::abs(fd - slope) < 1e-5 * std::abs(slope));
  }
  const std::vector<V3> mild = bent(s, 0.3);
  std::vector<V3> f1(x.size(), V3::Zero()), f2(x.size(), V3::Zero());
  const double e1 = in->energy(mild.data(), f1.data()).total;
  const double e2 = start.energy(mild.data(), f2.data()).total;
  CHECK(e1 == e2);
  CHECK(f1 == f2);

  // Off by default and without plasticity; the float shell refuses it.
  Shell elastic(s.points, s.weights, flat, dent_material(0.0), 3);
  elastic.set_plasticity_in_energy(true);
  CHECK_FALSE(elastic.plasticity_in_energy());
  shellmpm::KirchhoffLoveShellT<float> single(s.points, s.weights, flat, dent_material(1.5e3), 3);
  CHECK_THROWS(single.set_plasticity_in_energy(true));
}

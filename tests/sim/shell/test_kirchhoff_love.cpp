// Tests for the Kirchhoff-Love shell: quadrature rules, forces vs. finite differences
// of the energy, zero force at rest, patch test, membrane and bending stiffness.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <vector>

#include "sim/core/parallel.h"
#include "sim/shell/kirchhoff_love.h"
#include "sim/shell/shell_quadrature.h"
#include "tests/support/bezier_test_basis.h"

namespace {

using namespace shellmpm_test;

using Shell = shellmpm::KirchhoffLoveShellT<double>;
using V3 = Eigen::Vector3d;

shellmpm::ShellMaterialDesc test_material(double t = 0.02) {
  shellmpm::ShellMaterialDesc m;
  m.youngs_modulus = 1e5;
  m.poisson_ratio = 0.3;
  m.density = 800;
  m.thickness = t;
  return m;
}

Shell make_shell(const BezierShell& s, const std::vector<V3>& rest,
                 const shellmpm::ShellMaterialDesc& mat, int layers = 3) {
  return Shell(s.points, s.weights, rest, mat, layers);
}

double energy_of(const Shell& sh, const std::vector<V3>& x) {
  return sh.energy(x.data(), nullptr).total;
}

std::vector<V3> forces_of(const Shell& sh, const std::vector<V3>& x, bool serial = false) {
  std::vector<V3> f(x.size(), V3::Zero());
  sh.energy(x.data(), f.data(), serial);
  return f;
}

double max_norm(const std::vector<V3>& f) {
  double m = 0;
  for (const V3& v : f) m = std::max(m, v.norm());
  return m;
}

// |central difference of E along dir - (-f . dir)|.
double fd_error(const Shell& sh, const std::vector<V3>& x, const std::vector<V3>& dir, double eps,
                double* analytic = nullptr) {
  const std::vector<V3> f = forces_of(sh, x);
  double a = 0;
  for (std::size_t i = 0; i < x.size(); ++i) a -= f[i].dot(dir[i]);
  std::vector<V3> xp = x, xm = x;
  for (std::size_t i = 0; i < x.size(); ++i) {
    xp[i] += eps * dir[i];
    xm[i] -= eps * dir[i];
  }
  const double fd = (energy_of(sh, xp) - energy_of(sh, xm)) / (2 * eps);
  if (analytic) *analytic = a;
  return std::abs(fd - a);
}

void check_fd(const Shell& sh, const std::vector<V3>& x, std::mt19937& rng) {
  std::normal_distribution<double> nd(0.0, 1.0);
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<V3> dir(x.size());
    for (V3& d : dir) d = V3(nd(rng), nd(rng), nd(rng));
    double a = 0;
    const double e4 = fd_error(sh, x, dir, 1e-4, &a);
    const double e5 = fd_error(sh, x, dir, 1e-5);
    INFO("analytic " << a << " err(1e-4) " << e4 << " err(1e-5) " << e5);
    CHECK(std::abs(a) > 0);
    CHECK((e5 < 0.05 * e4 || e5 < 1e-9 * std::abs(a)));
    CHECK(e4 < 1e-3 * std::abs(a));  // O(eps^2) truncation only
  }
}

V3 flat_map(const Eigen::Vector2d& uv) {
  return V3(uv.x(), uv.y(), 0.0);
}
V3 curved_map(const Eigen::Vector2d& uv) {
  return V3(uv.x(), uv.y(), 0.25 * std::sin(2.0 * uv.x()) * std::cos(1.5 * uv.y()));
}

std::vector<V3> perturbed(const std::vector<V3>& x, double amp, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-amp, amp);
  std::vector<V3> y = x;
  for (V3& v : y) v += V3(u(rng), u(rng), u(rng));
  return y;
}

}  // namespace

TEST_CASE("triangle and Gauss-Legendre rules integrate polynomials exactly", "[kl]") {
  for (int np : {1, 3, 6, 7}) {
    const shellmpm::TriangleQuadrature q = shellmpm::triangle_quadrature(np);
    REQUIRE(q.points.size() == std::size_t(np));
    for (int a = 0; a <= q.degree; ++a)
      for (int b = 0; a + b <= q.degree; ++b) {
        double s = 0;
        for (int i = 0; i < np; ++i)
          s += q.weights[i] * std::pow(q.points[i].x(), a) * std::pow(q.points[i].y(), b);
        const double exact = factorial(a) * factorial(b) / factorial(a + b + 2);
        INFO("rule " << np << " monomial " << a << "," << b);
        CHECK(s == Approx(exact).epsilon(1e-13));
      }
  }
  for (int np = 1; np <= 5; ++np) {
    const shellmpm::LineQuadrature q = shellmpm::gauss_legendre(np);
    for (int d = 0; d <= 2 * np - 1; ++d) {
      double s = 0;
      for (int i = 0; i < np; ++i) s += q.weights[i] * std::pow(q.points[i], d);
      const double exact = (d % 2) ? 0.0 : 2.0 / (d + 1);
      INFO("GL " << np << " degree " << d);
      CHECK(s == Approx(exact).margin(1e-14));
    }
  }
  CHECK_THROWS(shellmpm::triangle_quadrature(4));
  CHECK_THROWS(shellmpm::gauss_legendre(6));
}

TEST_CASE("KL energy and force vanish at rest, under translation and rotation", "[kl]") {
  const BezierShell s = make_bezier_grid(2, 3, 6);
  for (int curved = 0; curved < 2; ++curved) {
    const std::vector<V3> rest = interpolate(s, curved ? curved_map : flat_map);
    const Shell sh = make_shell(s, rest, test_material());
    // Force scale: a 1e-3 stretch.
    std::vector<V3> stretched = rest;
    for (V3& v : stretched) v.x() *= 1.001;
    const double scale = max_norm(forces_of(sh, stretched));
    REQUIRE(scale > 0);
    INFO("curved " << curved << " force scale " << scale);
    CHECK(std::abs(energy_of(sh, rest)) < 1e-20);
    CHECK(max_norm(forces_of(sh, rest)) < 1e-9 * scale);
    const Eigen::Matrix3d Rm = Eigen::AngleAxisd(0.7, V3(1, 2, 3).normalized()).toRotationMatrix();
    std::vector<V3> moved = rest;
    for (V3& v : moved) v = Rm * v + V3(3.0, -2.0, 5.0);
    CHECK(std::abs(energy_of(sh, moved)) < 1e-12 * energy_of(sh, stretched));
    CHECK(max_norm(forces_of(sh, moved)) < 1e-7 * scale);
  }
}

TEST_CASE("KL forces are the exact gradient of the energy (finite differences)", "[kl]") {
  std::mt19937 rng(7);
  const BezierShell s = make_bezier_grid(2, 3, 7);
  for (int curved = 0; curved < 2; ++curved) {
    const std::vector<V3> rest = interpolate(s, curved ? curved_map : flat_map);
    for (double t : {0.02, 0.1}) {
      const Shell sh = make_shell(s, rest, test_material(t), 3);
      for (int config = 0; config < 2; ++config) {
        INFO("curved " << curved << " t " << t << " config " << config);
        check_fd(sh, perturbed(rest, 0.05, rng), rng);
      }
    }
  }
  // Large deformation (folded, strongly compressed) and 2 thickness points.
  const std::vector<V3> rest = interpolate(s, flat_map);
  const Shell sh = make_shell(s, rest, test_material(0.05), 2);
  std::vector<V3> folded = interpolate(s, [](const Eigen::Vector2d& uv) {
    return V3(0.6 * std::sin(2.0 * uv.x()), 0.8 * uv.y(), 0.6 * (1 - std::cos(2.0 * uv.x())));
  });
  check_fd(sh, perturbed(folded, 0.02, rng), rng);
}

TEST_CASE("KL energy and forces do not depend on the thread count", "[kl]") {
  std::mt19937 rng(11);
  const BezierShell s = make_bezier_grid(8, 3, 7);  // 896 quadrature points: several chunks
  const std::vector<V3> rest = interpolate(s, curved_map);
  const Shell sh = make_shell(s, rest, test_material());
  const std::vector<V3> x = perturbed(rest, 0.01, rng);
  std::vector<V3> fs(x.size(), V3::Zero()), fp(x.size(), V3::Zero()), f1(x.size(), V3::Zero());
  const auto es = sh.energy(x.data(), fs.data(), true);
  const auto ep = sh.energy(x.data(), fp.data(), false);
  Shell::Energy e1;
  {
    shellmpm::ThreadLimit one(1);
    e1 = sh.energy(x.data(), f1.data(), false);
  }
  CHECK(es.total == ep.total);
  CHECK(es.membrane == ep.membrane);
  CHECK(e1.total == ep.total);
  for (std::size_t i = 0; i < x.size(); ++i) {
    CHECK(fs[i] == fp[i]);
    CHECK(f1[i] == fp[i]);
  }
  CHECK(sh.max_strain(x.data(), true) == sh.max_strain(x.data(), false));
  // Without the membrane/bending split: the same total and forces, bit for bit, and the
  // split marked as not computed.
  std::vector<V3> fn(x.size(), V3::Zero());
  const auto en = sh.energy(x.data(), fn.data(), false, false);
  CHECK(en.total == ep.total);
  CHECK(std::isnan(en.membrane));
  CHECK(std::isnan(en.bending));
  CHECK(ep.membrane > 0);
  for (std::size_t i = 0; i < x.size(); ++i) CHECK(fn[i] == fp[i]);
}

TEST_CASE("KL patch test: affine deformation gives uniform stress", "[kl]") {
  // Flat rest patch (a sheared parallelogram), arbitrary affine deformation plus a rigid
  // motion: the energy is area * t * psi(A), the bending part vanishes, and control points
  // whose basis functions vanish on the outer boundary feel no force.
  const BezierShell s = make_bezier_grid(2, 4, 7);
  const auto rest_map = [](const Eigen::Vector2d& uv) {
    return V3(1.2 * uv.x() + 0.3 * uv.y(), 0.9 * uv.y(), 0.0);
  };
  const std::vector<V3> rest = interpolate(s, rest_map);
  const shellmpm::ShellMaterialDesc mat = test_material();
  const Shell sh = make_shell(s, rest, mat);
  Eigen::Matrix2d A2;
  A2 << 1.15, 0.12, -0.05, 0.92;  // in-plane deformation of the rest plane
  const Eigen::Matrix3d Rm =
      Eigen::AngleAxisd(0.4, V3(0.3, -1, 0.5).normalized()).toRotationMatrix();
  std::vector<V3> x = rest;
  for (V3& v : x) {
    const Eigen::Vector2d p = A2 * v.head<2>();
    v = Rm * V3(p.x(), p.y(), 0.0) + V3(0.1, 0.2, 0.3);
  }
  const Eigen::JacobiSVD<Eigen::Matrix2d> svd(A2);
  const double l1 = std::log(svd.singularValues()(0)), l2 = std::log(svd.singularValues()(1));
  const double mu = mat.youngs_modulus / (2 * (1 + mat.poisson_ratio));
  const double lam =
      mat.youngs_modulus * mat.poisson_ratio / (1 - mat.poisson_ratio * mat.poisson_ratio);
  const double psi = mu * (l1 * l1 + l2 * l2) + 0.5 * lam * (l1 + l2) * (l1 + l2);
  std::vector<V3> f(x.size(), V3::Zero());
  const auto e = sh.energy(x.data(), f.data());
  const double area = 1.2 * 0.9;
  CHECK(sh.rest_area() == Approx(area).epsilon(1e-12));
  CHECK(e.total == Approx(area * mat.thickness * psi).epsilon(1e-10));
  CHECK(std::abs(e.bending) < 1e-10 * e.total);
  const double scale = max_norm(f);
  V3 sum = V3::Zero();
  int interior = 0;
  for (std::size_t j = 0; j < x.size(); ++j) {
    sum += f[j];
    const Eigen::Vector2d uv = s.node_uv[j];
    const bool on_boundary =
        uv.x() < 1e-12 || uv.y() < 1e-12 || uv.x() > 1 - 1e-12 || uv.y() > 1 - 1e-12;
    if (!on_boundary) {
      ++interior;
      CHECK(f[j].norm() < 1e-10 * scale);
    }
  }
  CHECK(interior == 49);
  CHECK(sum.norm() < 1e-10 * scale);  // momentum conservation
}

TEST_CASE("KL small-strain membrane stiffness is E t / (1 - nu^2)", "[kl]") {
  const BezierShell s = make_bezier_grid(2, 3, 6);
  const std::vector<V3> rest = interpolate(s, flat_map);
  const shellmpm::ShellMaterialDesc mat = test_material(0.01);
  const Shell sh = make_shell(s, rest, mat);
  const double eps = 1e-4;
  std::vector<V3> x = rest;
  for (V3& v : x) v.x() *= 1 + eps;  // uniaxial strain (eps_22 = 0)
  const auto e = sh.energy(x.data(), nullptr);
  const double Cm =
      mat.youngs_modulus * mat.thickness / (1 - mat.poisson_ratio * mat.poisson_ratio);
  CHECK(e.total / sh.rest_area() == Approx(0.5 * Cm * eps * eps).epsilon(0.01));
  CHECK(e.membrane == Approx(e.total).epsilon(1e-6));
  // Equi-biaxial: energy per area = Cm (1 + nu) eps^2.
  x = rest;
  for (V3& v : x) v.head<2>() *= 1 + eps;
  CHECK(sh.energy(x.data(), nullptr).total / sh.rest_area() ==
        Approx(Cm * (1 + mat.poisson_ratio) * eps * eps).epsilon(0.01));
}

TEST_CASE("KL small-strain bending stiffness is E t^3 / (12 (1 - nu^2))", "[kl]") {
  const BezierShell s = make_bezier_grid(2, 5, 7);
  const shellmpm::ShellMaterialDesc mat = test_material(0.01);
  const double D = mat.youngs_modulus * std::pow(mat.thickness, 3) /
                   (12 * (1 - mat.poisson_ratio * mat.poisson_ratio));
  const double kappa = 0.2, R = 1 / kappa;
  const auto cylinder = [R](const Eigen::Vector2d& uv) {
    return V3(R * std::sin(uv.x() / R), uv.y(), R * (1 - std::cos(uv.x() / R)));
  };
  for (int layers : {2, 3, 5}) {
    // Flat rest, bent to a cylinder of curvature kappa: energy per area D kappa^2 / 2.
    const std::vector<V3> flat = interpolate(s, flat_map);
    const std::vector<V3> bent = interpolate(s, cylinder);
    const Shell sh = make_shell(s, flat, mat, layers);
    const auto e = sh.energy(bent.data(), nullptr);
    INFO("layers " << layers << " total " << e.total << " membrane " << e.membrane);
    CHECK(e.total / sh.rest_area() == Approx(0.5 * D * kappa * kappa).epsilon(0.01));
    CHECK(e.bending == Approx(e.total).epsilon(0.01));
    // Curved rest (cylinder), flattened: the same energy.
    const Shell shc = make_shell(s, bent, mat, layers);
    CHECK(shc.energy(flat.data(), nullptr).total / shc.rest_area() ==
          Approx(0.5 * D * kappa * kappa).epsilon(0.01));
  }
}

TEST_CASE("KL lumped masses are positive and sum to rho t area", "[kl]") {
  const BezierShell s = make_bezier_grid(3, 3, 6);
  const std::vector<V3> rest = interpolate(s, curved_map);
  const shellmpm::ShellMaterialDesc mat = test_material();
  const Shell sh = make_shell(s, rest, mat);
  const std::vector<double> m = sh.lumped_masses(rest.size());
  double sum = 0;
  for (double v : m) {
    CHECK(v > 0);
    sum += v;
  }
  CHECK(sum == Approx(mat.density * mat.thickness * sh.rest_area()).epsilon(1e-12));
  CHECK(sh.rest_area() > 1.0);  // curved surface over the unit square
  CHECK(sh.plastic_state().empty());
}

TEST_CASE("KL float evaluation matches double", "[kl]") {
  std::mt19937 rng(3);
  const BezierShell s = make_bezier_grid(2, 3, 6);
  const std::vector<V3> rest = interpolate(s, curved_map);
  const Shell shd = make_shell(s, rest, test_material());
  const shellmpm::KirchhoffLoveShellT<float> shf(s.points, s.weights, rest, test_material(), 3);
  const std::vector<V3> x = perturbed(rest, 0.03, rng);
  std::vector<Eigen::Vector3f> xf(x.size()), ff(x.size(), Eigen::Vector3f::Zero());
  for (std::size_t i = 0; i < x.size(); ++i) xf[i] = x[i].cast<float>();
  const std::vector<V3> fd = forces_of(shd, x);
  const double ed = energy_of(shd, x);
  const float ef = shf.energy(xf.data(), ff.data()).total;
  CHECK(ef == Approx(ed).epsilon(1e-3));
  const double scale = max_norm(fd);
  for (std::size_t i = 0; i < x.size(); ++i)
    CHECK((ff[i].cast<double>() - fd[i]).norm() < 2e-3 * scale);
}

// ---- Large-stretch stiffening (kirchhoff_love.h; issue 10) ----

namespace {

/// The rest patch's (x, y) mapped by Rot(0.7) diag(s1, s2) Rot(0.3), z kept, then a
/// rotation: for a flat rest an affine stretch with singular values s1, s2.
std::vector<V3> affine_stretch(const std::vector<V3>& rest, double s1, double s2) {
  const Eigen::Matrix2d U = Eigen::Rotation2Dd(0.7).toRotationMatrix();
  const Eigen::Matrix2d W = Eigen::Rotation2Dd(-0.3).toRotationMatrix();
  const Eigen::Matrix2d A = U * Eigen::Vector2d(s1, s2).asDiagonal() * W.transpose();
  const Eigen::Matrix3d Rm =
      Eigen::AngleAxisd(0.4, V3(0.3, -1, 0.5).normalized()).toRotationMatrix();
  std::vector<V3> x = rest;
  for (V3& v : x) {
    const Eigen::Vector2d p = A * v.head<2>();
    v = Rm * V3(p.x(), p.y(), v.z());
  }
  return x;
}

/// Membrane force resultant along x of the patch stretched by (s1, s2) along (x, y):
/// dE/ds1 [N m] from the kernel's forces (x_j = (s1 X_j, s2 Y_j, 0), dx_j/ds1 = (X_j, 0, 0)).
double force_along_x(const Shell& sh, const std::vector<V3>& rest, double s1, double s2,
                     double* energy) {
  std::vector<V3> x = rest;
  for (V3& v : x) {
    v.x() *= s1;
    v.y() *= s2;
  }
  std::vector<V3> f(x.size(), V3::Zero());
  *energy = sh.energy(x.data(), f.data()).total;
  double dE = 0;
  for (std::size_t j = 0; j < x.size(); ++j) dE -= f[j].x() * rest[j].x();
  return dE;
}

}  // namespace

TEST_CASE("KL stretch term: energy of an affine stretch is Hencky + k (s - s_l)_+^2",
          "[kl][membrane_stretch]") {
  const BezierShell s = make_bezier_grid(2, 3, 7);
  const std::vector<V3> rest = interpolate(s, flat_map);
  for (double nu : {0.0, 0.3, 0.45}) {
    shellmpm::ShellMaterialDesc mat = test_material(0.01);
    mat.poisson_ratio = nu;
    const Shell sh = make_shell(s, rest, mat);
    const shellmpm::KirchhoffLoveShellT<float> shf(s.points, s.weights, rest, mat, 3);
    const double E = mat.youngs_modulus, sl = mat.stretch_limit;
    const double k = 0.225 * E / (1 - nu);
    CHECK(sl == 1.5);
    CHECK(sh.stretch_limit() == sl);
    CHECK(sh.stretch_stiffness() == Approx(k).epsilon(1e-14));
    const double mu = E / (2 * (1 + nu)), lam = E * nu / (1 - nu * nu);
    // Below, one beyond, both beyond (equal singular values exactly), both beyond unequal,
    // one beyond with the other compressed.
    for (const auto& st : std::vector<std::pair<double, double>>{
             {1.4, 1.2}, {3.0, 1.0}, {3.0, 3.0}, {2.5, 1.8}, {1.51, 1.49}, {4.0, 0.7}}) {
      const double l1 = std::log(st.first), l2 = std::log(st.second);
      const double d1 = std::max(st.first - sl, 0.0), d2 = std::max(st.second - sl, 0.0);
      const double psi =
          mu * (l1 * l1 + l2 * l2) + 0.5 * lam * (l1 + l2) * (l1 + l2) + k * (d1 * d1 + d2 * d2);
      const std::vector<V3> x = affine_stretch(rest, st.first, st.second);
      const auto e = sh.energy(x.data(), nullptr);
      INFO("nu " << nu << " s " << st.first << ", " << st.second);
      CHECK(e.total == Approx(mat.thickness * psi).epsilon(1e-10));  // unit area
      CHECK(std::abs(e.bending) < 1e-9 * e.total);
      std::vector<Eigen::Vector3f> xf(x.size());
      for (std::size_t i = 0; i < x.size(); ++i) xf[i] = x[i].cast<float>();
      CHECK(shf.energy(xf.data(), nullptr).total == Approx(e.total).epsilon(1e-4));
    }
  }
}

TEST_CASE("KL stretch term: forces are the gradient of the energy past the limit",
          "[kl][membrane_stretch]") {
  std::mt19937 rng(17);
  const BezierShell s = make_bezier_grid(2, 3, 7);
  for (int curved = 0; curved < 2; ++curved) {
    const std::vector<V3> rest = interpolate(s, curved ? curved_map : flat_map);
    for (double t : {0.02, 0.1}) {
      const Shell sh = make_shell(s, rest, test_material(t), 3);
      // One stretch beyond the limit, both (nearly equal), one far past with the other
      // compressed, and (flat, affine: uniform) both just past it. Every point stays clear
      // of the kink at s_l, where the central difference is only first order.
      for (const auto& st : std::vector<std::pair<double, double>>{
               {3.0, 1.0}, {2.5, 2.5}, {4.5, 0.7}, {1.56, 1.54}}) {
        const bool near_limit = st.first < 2;
        if (near_limit && curved) continue;  // a curved rest would spread s across s_l
        std::vector<V3> x = affine_stretch(rest, st.first, st.second);
        if (!near_limit) x = perturbed(x, 0.01, rng);
        INFO("curved " << curved << " t " << t << " s " << st.first << ", " << st.second);
        REQUIRE(sh.max_strain(x.data()) > std::log(sh.stretch_limit()));
        check_fd(sh, x, rng);
      }
    }
  }
}

TEST_CASE("KL stretch term: float matches double, and nothing changes below the limit",
          "[kl][membrane_stretch]") {
  std::mt19937 rng(5);
  const BezierShell s = make_bezier_grid(2, 3, 6);
  const std::vector<V3> rest = interpolate(s, curved_map);
  {  // past the limit: the float kernel follows the double one
    const Shell shd = make_shell(s, rest, test_material());
    const shellmpm::KirchhoffLoveShellT<float> shf(s.points, s.weights, rest, test_material(), 3);
    const std::vector<V3> x = perturbed(affine_stretch(rest, 3.0, 2.0), 0.03, rng);
    std::vector<Eigen::Vector3f> xf(x.size()), ff(x.size(), Eigen::Vector3f::Zero());
    for (std::size_t i = 0; i < x.size(); ++i) xf[i] = x[i].cast<float>();
    const std::vector<V3> fd = forces_of(shd, x);
    CHECK(shf.energy(xf.data(), ff.data()).total == Approx(energy_of(shd, x)).epsilon(1e-3));
    const double scale = max_norm(fd);
    for (std::size_t i = 0; i < x.size(); ++i)
      CHECK((ff[i].cast<double>() - fd[i]).norm() < 2e-3 * scale);
  }
  // Below the limit the energy and forces are bitwise those of a higher limit (plain Hencky).
  shellmpm::ShellMaterialDesc high = test_material();
  high.stretch_limit = Shell::kMaxStretchLimit;
  const Shell sh = make_shell(s, rest, test_material()), shh = make_shell(s, rest, high);
  const shellmpm::KirchhoffLoveShellT<float> shf(s.points, s.weights, rest, test_material(), 3);
  const shellmpm::KirchhoffLoveShellT<float> shfh(s.points, s.weights, rest, high, 3);
  const std::vector<V3> x = perturbed(affine_stretch(rest, 1.3, 0.9), 0.02, rng);
  REQUIRE(sh.max_strain(x.data()) < std::log(1.45));
  const std::vector<V3> f = forces_of(sh, x), fh = forces_of(shh, x);
  const auto e = sh.energy(x.data(), nullptr), eh = shh.energy(x.data(), nullptr);
  CHECK(e.total == eh.total);
  CHECK(e.membrane == eh.membrane);
  std::vector<Eigen::Vector3f> xf(x.size()), ff(x.size(), Eigen::Vector3f::Zero()),
      ffh(x.size(), Eigen::Vector3f::Zero());
  for (std::size_t i = 0; i < x.size(); ++i) xf[i] = x[i].cast<float>();
  CHECK(shf.energy(xf.data(), ff.data()).total == shfh.energy(xf.data(), ffh.data()).total);
  for (std::size_t i = 0; i < x.size(); ++i) {
    CHECK(f[i] == fh[i]);
    CHECK(ff[i] == ffh[i]);
  }
}

TEST_CASE("KL membrane force of a stretched element grows monotonically from s = 1 to 5",
          "[kl][membrane_stretch]") {
  // Plain Hencky peaks at s = e (uniaxial strain: (2 mu + lambda) log(s) / s) and fails here.
  const BezierShell s = make_bezier_grid(1, 2, 3);
  const std::vector<V3> rest = interpolate(s, flat_map);
  for (double nu : {0.0, 0.3, 0.45}) {
    shellmpm::ShellMaterialDesc mat = test_material(0.01);
    mat.poisson_ratio = nu;
    const Shell sh = make_shell(s, rest, mat);
    // Lateral stretch held at 1 (uniaxial strain), contracted, and stretched a little.
    for (double s2 : {1.0, 0.8, 1.25}) {
      double e_prev = 0;
      double f_prev = force_along_x(sh, rest, 1.0, s2, &e_prev);
      for (int i = 1; i <= 200; ++i) {
        const double s1 = 1.0 + 4.0 * i / 200;
        double e = 0;
        const double f = force_along_x(sh, rest, s1, s2, &e);
        INFO("nu " << nu << " s2 " << s2 << " s1 " << s1 << " force " << f << " previous "
                   << f_prev);
        REQUIRE(std::isfinite(f));
        REQUIRE(f > f_prev);                 // d2E/ds1^2 > 0
        if (s1 > 1.25) REQUIRE(e > e_prev);  // past the lateral stretch: dE/ds1 > 0
        f_prev = f;
        e_prev = e;
      }
    }
  }
}

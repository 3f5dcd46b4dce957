// Tests of the deformation-dependent wave speed of sim/mpm/constitutive.h
// (ConstitutiveModelT::wave_modulus / wave_speed(F, ...), used by Solver::stable_dt):
// the rest value at F = I, the bound against the spatial longitudinal wave speed from
// finite differences of the Kirchhoff stress along the principal stretches, tightness
// where the cheap stretch bound is exact, and the stiffening of neo-Hookean under
// compression (which the rest-state speed misses).
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "sim/mpm/constitutive.h"

namespace {

using shellmpm::ConstitutiveModelT;
using shellmpm::ElasticModel;
using shellmpm::MaterialDesc;
using shellmpm::MaterialKind;
using Model = ConstitutiveModelT<double>;
using Mat3d = Eigen::Matrix3d;
using Vec3d = Eigen::Vector3d;

MaterialDesc desc(const std::string& name, MaterialKind kind, ElasticModel model) {
  MaterialDesc d;
  d.name = name;
  d.kind = kind;
  d.model = model;
  d.youngs_modulus = 1e5;
  d.poisson_ratio = 0.3;
  return d;
}

struct Named {
  std::string name;
  MaterialDesc desc;
};
std::vector<Named> all_descs() {
  MaterialDesc sand_c = desc("sand", MaterialKind::Sand, ElasticModel::FixedCorotated);
  sand_c.cohesion = 0.01;
  MaterialDesc snow = desc("snow", MaterialKind::Snow, ElasticModel::FixedCorotated);
  snow.poisson_ratio = 0.2;
  MaterialDesc nh_stiff = desc("nh", MaterialKind::Elastic, ElasticModel::NeoHookean);
  nh_stiff.poisson_ratio = 0.45;
  return {{"fixed corotated", desc("fcr", MaterialKind::Elastic, ElasticModel::FixedCorotated)},
          {"neo-Hookean", desc("nh", MaterialKind::Elastic, ElasticModel::NeoHookean)},
          {"neo-Hookean nu 0.45", nh_stiff},
          {"sand", desc("sand", MaterialKind::Sand, ElasticModel::FixedCorotated)},
          {"sand with cohesion", sand_c},
          {"snow", snow}};
}

Mat3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

/// Principal Kirchhoff stress u_i^T tau(F) u_i of F = U diag(sigma) V^T.
double principal_tau(const Model& m, const Mat3d& U, const Vec3d& sigma, const Mat3d& V, int i,
                     double plastic) {
  const Mat3d tau = m.kirchhoff(U * sigma.asDiagonal() * V.transpose(), plastic);
  return U.col(i).dot(tau * U.col(i));
}

/// rho0 c_i^2 = d tau_i / d ln sigma_i - tau_i by central differences in ln sigma_i.
double fd_modulus(const Model& m, const Mat3d& U, const Vec3d& sigma, const Mat3d& V, int i,
                  double plastic, double h) {
  Vec3d sp = sigma, sm = sigma;
  sp(i) *= std::exp(h);
  sm(i) *= std::exp(-h);
  const double dtau =
      (principal_tau(m, U, sp, V, i, plastic) - principal_tau(m, U, sm, V, i, plastic)) / (2 * h);
  return dtau - principal_tau(m, U, sigma, V, i, plastic);
}

/// Largest principal longitudinal modulus max_i rho0 c_i^2 by finite differences; checks
/// the difference quotient has converged (h and h/2 agree).
double true_modulus(const Model& m, const Mat3d& U, const Vec3d& sigma, const Mat3d& V,
                    double plastic) {
  double q = -1e300;
  const double scale = m.lambda + 2 * m.mu;
  for (int i = 0; i < 3; ++i) {
    const double a = fd_modulus(m, U, sigma, V, i, plastic, 1e-4);
    const double b = fd_modulus(m, U, sigma, V, i, plastic, 5e-5);
    REQUIRE(std::abs(a - b) < 1e-6 * scale);
    q = std::max(q, b);
  }
  return q;
}

}  // namespace

TEMPLATE_TEST_CASE("wave speed: F = I gives the rest value sqrt((lambda + 2 mu) / rho)",
                   "[constitutive][wave_speed]", float, double) {
  using T = TestType;
  using M = ConstitutiveModelT<T>;
  using Mat3T = typename M::Mat3T;
  const Mat3T I = Mat3T::Identity();
  for (const Named& nd : all_descs()) {
    INFO(nd.name);
    const M m = M::from_desc(nd.desc);
    for (T jp : {T(0.7), T(1), T(1.3)}) {
      const T p = m.kind == MaterialKind::Snow ? jp : m.initial_plastic();
      const T h = m.hardening(p);
      const T rho = T(1100);
      CHECK(m.wave_modulus(I, p) == (m.lambda + T(2) * m.mu) * h);
      CHECK(m.wave_speed(I, rho, p) == std::sqrt((m.lambda + T(2) * m.mu) * h / rho));
      CHECK(m.wave_speed(I, rho, p) == m.wave_speed(rho, p));
    }
  }
  // A rotation is a rest state too (up to rounding).
  std::mt19937 rng(7);
  for (const Named& nd : all_descs()) {
    INFO(nd.name);
    const M m = M::from_desc(nd.desc);
    const T p = m.initial_plastic();
    for (int k = 0; k < 20; ++k) {
      const Mat3T R = random_rotation(rng).cast<T>();
      CHECK(m.wave_speed(R, T(1000), p) ==
            Approx(m.wave_speed(T(1000), p)).epsilon(sizeof(T) == 4 ? 1e-3 : 1e-6));
    }
  }
}

TEST_CASE("wave speed: bounds the spatial longitudinal speed from finite differences of tau",
          "[constitutive][wave_speed]") {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (const Named& nd : all_descs()) {
    INFO(nd.name);
    const Model m = Model::from_desc(nd.desc);
    const double scale = m.lambda + 2 * m.mu;
    std::vector<Vec3d> stretches = {{0.2, 1.0, 1.0},       {1.0, 0.2, 1.0},   {0.45, 0.45, 1.0},
                                    {0.585, 0.585, 0.585}, {2.0, 1.0, 1.0},   {1.6, 1.6, 1.0},
                                    {1.5, 1.5, 1.5},       {2.0, 0.5, 0.2},   {0.3, 1.2, 0.6},
                                    {1.0, 1.0, 1.0},       {1.02, 0.99, 0.97}};
    for (int k = 0; k < 400; ++k) {
      // log J uniform in [log 0.2, log 3], then a deviatoric log-stretch of up to +-0.6.
      const double lj = std::log(0.2) + u01(rng) * (std::log(3.0) - std::log(0.2));
      Vec3d d(u01(rng), u01(rng), u01(rng));
      d = 1.2 * (d.array() - 0.5).matrix();
      d.array() -= d.mean();
      stretches.push_back((lj / 3 + d.array()).exp().matrix());
    }
    double worst = 1e300, loosest = 0;
    for (const Vec3d& s : stretches) {
      const Mat3d U = random_rotation(rng), V = random_rotation(rng);
      const Mat3d F = U * s.asDiagonal() * V.transpose();
      const auto* snow = std::get_if<shellmpm::SnowT<double>>(&m.model);
      const double plastic =
          snow ? snow->jp_min + u01(rng) * (snow->jp_max - snow->jp_min) : m.initial_plastic();
      const double bound = m.wave_modulus(F, plastic);
      const double truth = true_modulus(m, U, s, V, plastic);
      INFO("sigma " << s.transpose() << ", J " << s.prod() << ", plastic " << plastic << ": bound "
                    << bound << ", finite differences " << truth);
      const double h = m.hardening(plastic);
      CHECK(bound >= truth - 1e-7 * scale * h);
      CHECK(std::isfinite(bound));
      // The speed itself: the same bound on sqrt(max(truth, 0) / rho0).
      CHECK(m.wave_speed(F, 1000.0, plastic) >=
            std::sqrt(std::max(truth - 1e-7 * scale * h, 0.0) / 1000.0));
      worst = std::min(worst, (bound - truth) / (scale * h));
      if (truth > 0.05 * scale * h) loosest = std::max(loosest, bound / truth);
    }
    // Not absurdly loose: within a factor of 2 in rho0 c^2 over these states (the
    // Frobenius bound sigma_max^2 <= |F|^2 alone would not be exact at rest).
    CHECK(loosest < 2.0);
    CHECK(worst > -1e-7);
  }
}

TEST_CASE("wave speed: exact where the stretch bound is exact", "[constitutive][wave_speed]") {
  // Uniaxial stretch along a rotated axis: sigma_max^2 is bounded exactly (elastic
  // models); uniaxial compression: sigma_min^2 and log J exactly (sand).
  std::mt19937 rng(11);
  for (const Named& nd : all_descs()) {
    INFO(nd.name);
    const Model m = Model::from_desc(nd.desc);
    const bool sand = m.kind == MaterialKind::Sand;
    for (double a :
         sand ? std::vector<double>{0.2, 0.5, 0.9} : std::vector<double>{1.1, 1.5, 2.5}) {
      const Mat3d U = random_rotation(rng), V = random_rotation(rng);
      const Vec3d s(1.0, a, 1.0);
      const double plastic = m.kind == MaterialKind::Snow ? 1.2 : m.initial_plastic();
      const double bound = m.wave_modulus(U * s.asDiagonal() * V.transpose(), plastic);
      const double truth = true_modulus(m, U, s, V, plastic);
      INFO("a " << a);
      CHECK(bound == Approx(truth).epsilon(1e-6));
    }
  }
}

TEST_CASE("wave speed: neo-Hookean stiffens under compression", "[constitutive][wave_speed]") {
  // The jelly of scenes/mesh_source.yaml.
  MaterialDesc d = desc("jelly", MaterialKind::Elastic, ElasticModel::NeoHookean);
  d.youngs_modulus = 3e4;
  d.poisson_ratio = 0.35;
  const Model m = Model::from_desc(d);
  const double rho = 1100, rest = m.wave_speed(rho, 0.0);
  std::mt19937 rng(3);
  double prev = rest;
  for (double J : {0.9, 0.7, 0.5, 0.3, 0.2}) {
    INFO("J " << J);
    const Mat3d R = random_rotation(rng);
    // Uniform and uniaxial compression to volume ratio J.
    for (const Vec3d& s : {Vec3d(Vec3d::Constant(std::cbrt(J))), Vec3d(J, 1.0, 1.0)}) {
      const Mat3d F = R * s.asDiagonal();
      const double c = m.wave_speed(F, rho, 0.0);
      const double c_true = std::sqrt(true_modulus(m, R, s, Mat3d::Identity(), 0.0) / rho);
      CHECK(c_true > rest);  // the rest-state speed is not a bound here
      if (J <= 0.5) CHECK(c_true > 1.05 * rest);
      CHECK(c >= c_true * (1 - 1e-9));
    }
    const double c_uniform = m.wave_speed(R * std::cbrt(J), rho, 0.0);
    CHECK(c_uniform > prev);
    prev = c_uniform;
  }
}

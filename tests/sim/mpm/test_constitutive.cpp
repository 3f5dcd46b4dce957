// Tests of sim/mpm/constitutive.h: finite-difference checks of P against the energy
// (asserting the error shrinks with epsilon), tau = P F^T, zero stress and energy at rest,
// rotation invariance, Drucker-Prager and snow return mappings, batch == per-particle,
// and the float instantiation against double.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "sim/math/svd3.h"
#include "sim/mpm/constitutive.h"

namespace {

using shellmpm::ConstitutiveModelT;
using shellmpm::ElasticModel;
using shellmpm::MaterialDesc;
using shellmpm::MaterialKind;
using Model = ConstitutiveModelT<double>;
using Mat3d = Eigen::Matrix3d;
using Vec3d = Eigen::Vector3d;

MaterialDesc desc_fcr() {
  MaterialDesc d;
  d.name = "fcr";
  d.kind = MaterialKind::Elastic;
  d.model = ElasticModel::FixedCorotated;
  d.youngs_modulus = 1e5;
  d.poisson_ratio = 0.3;
  return d;
}
MaterialDesc desc_nh() {
  MaterialDesc d = desc_fcr();
  d.name = "nh";
  d.model = ElasticModel::NeoHookean;
  return d;
}
MaterialDesc desc_sand(double cohesion) {
  MaterialDesc d = desc_fcr();
  d.name = "sand";
  d.kind = MaterialKind::Sand;
  d.youngs_modulus = 3.5e5;
  d.friction_angle_deg = 30.0;
  d.cohesion = cohesion;
  return d;
}
MaterialDesc desc_snow() {
  MaterialDesc d = desc_fcr();
  d.name = "snow";
  d.kind = MaterialKind::Snow;
  d.youngs_modulus = 1.4e5;
  d.poisson_ratio = 0.2;
  return d;
}

struct Named {
  std::string name;
  Model model;
};
std::vector<Named> all_models() {
  return {{"fixed corotated", Model::from_desc(desc_fcr())},
          {"neo-Hookean", Model::from_desc(desc_nh())},
          {"sand", Model::from_desc(desc_sand(0.0))},
          {"sand with cohesion", Model::from_desc(desc_sand(0.01))},
          {"snow", Model::from_desc(desc_snow())}};
}

Mat3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}
Mat3d random_matrix(std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  return Mat3d::NullaryExpr([&]() { return u(rng); });
}
/// Deformation gradients for derivative checks: near identity and moderately deformed,
/// all with det > 0.
std::vector<Mat3d> test_deformations(std::mt19937& rng) {
  std::vector<Mat3d> out;
  for (int i = 0; i < 4; ++i) out.push_back(Mat3d::Identity() + random_matrix(rng, 0.05));
  for (int i = 0; i < 4; ++i)
    out.push_back(random_rotation(rng) * Vec3d(1.3, 0.8, 0.9).asDiagonal() *
                      random_rotation(rng).transpose() +
                  random_matrix(rng, 0.15));
  for (int i = 0; i < 2; ++i)
    out.push_back(random_rotation(rng) * (Mat3d::Identity() + random_matrix(rng, 0.2)));
  for (const Mat3d& F : out) REQUIRE(F.determinant() > 0.2);
  return out;
}

double stress_scale(const Model& m) {
  return m.mu + m.lambda;
}

/// Central-difference dpsi/dF with step h.
Mat3d fd_piola(const Model& m, const Mat3d& F, double plastic, double h) {
  Mat3d P;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Mat3d Fp = F, Fm = F;
      Fp(i, j) += h;
      Fm(i, j) -= h;
      P(i, j) = (m.energy(Fp, plastic) - m.energy(Fm, plastic)) / (2 * h);
    }
  return P;
}

/// Relative FD errors at h = 1e-3, 1e-4, 1e-5; asserts they fall (or hit a floor).
void check_fd(const Model& m, const Mat3d& F, double plastic) {
  const Mat3d P = m.first_piola(F, plastic);
  const double scale = P.norm() + stress_scale(m) * m.hardening(plastic);
  double err[3];
  const double hs[3] = {1e-3, 1e-4, 1e-5};
  for (int k = 0; k < 3; ++k) err[k] = (fd_piola(m, F, plastic, hs[k]) - P).norm() / scale;
  const double floor = 1e-8;
  INFO("F =\n"
       << F << "\nplastic = " << plastic << "\nrelative FD errors: " << err[0] << ", " << err[1]
       << ", " << err[2]);
  // The h = 1e-3 error must be a real truncation error, not already at round-off,
  // otherwise the test could not tell a wrong P from a right one.
  CHECK(err[0] < 1e-4);
  CHECK((err[1] < 0.05 * err[0] || err[1] < floor));
  CHECK((err[2] < 0.05 * err[1] || err[2] < floor));
  CHECK(err[2] < 1e-7);
}

bool same_bits(const Mat3d& a, const Mat3d& b) {
  return std::memcmp(a.data(), b.data(), sizeof(double) * 9) == 0;
}

/// Hencky strain of F, sorted like svd3's sigma.
Vec3d hencky(const Mat3d& F) {
  Mat3d U, V;
  Vec3d s;
  shellmpm::svd3(F, U, s, V);
  return s.array().abs().log().matrix();
}

}  // namespace

namespace {
// The parameters of a model built by from_desc.
const shellmpm::DruckerPragerT<double>& dp_of(const Model& m) {
  return std::get<shellmpm::DruckerPragerT<double>>(m.model);
}
const shellmpm::SnowT<double>& snow_of(const Model& m) {
  return std::get<shellmpm::SnowT<double>>(m.model);
}
}  // namespace

TEST_CASE("constitutive: from_desc parameters", "[constitutive]") {
  const Model fcr = Model::from_desc(desc_fcr());
  CHECK(fcr.mu == Approx(1e5 / 2.6));
  CHECK(fcr.lambda == Approx(1e5 * 0.3 / (1.3 * 0.4)));
  CHECK_FALSE(fcr.has_plasticity());
  CHECK(fcr.initial_plastic() == 0.0);
  const Model sand_m = Model::from_desc(desc_sand(0.02));
  REQUIRE(std::holds_alternative<shellmpm::DruckerPragerT<double>>(sand_m.model));
  const auto& sand = std::get<shellmpm::DruckerPragerT<double>>(sand_m.model);
  CHECK(sand.alpha == Approx(std::sqrt(2.0 / 3.0) * 2 * 0.5 / 2.5));  // sin 30 deg = 1/2
  CHECK(sand.cohesion == Approx(0.02));
  CHECK(sand_m.has_plasticity());
  CHECK(sand_m.initial_plastic() == 0.0);
  const Model snow_m = Model::from_desc(desc_snow());
  CHECK(snow_m.has_plasticity());
  CHECK(snow_m.initial_plastic() == 1.0);
  REQUIRE(std::holds_alternative<shellmpm::SnowT<double>>(snow_m.model));
  const auto& snow = std::get<shellmpm::SnowT<double>>(snow_m.model);
  CHECK(snow.theta_c == Approx(2.5e-2));
  CHECK(snow.theta_s == Approx(7.5e-3));
  CHECK(snow.xi == Approx(10.0));
  CHECK(snow.jp_min == Approx(0.6));
  CHECK(snow.jp_max == Approx(20.0));
  MaterialDesc bad = desc_fcr();
  bad.poisson_ratio = 0.5;
  CHECK_THROWS_AS(Model::from_desc(bad), shellmpm::InvariantError);
}

TEST_CASE("constitutive: first Piola matches finite differences of the energy", "[constitutive]") {
  std::mt19937 rng(11);
  const std::vector<Mat3d> Fs = test_deformations(rng);
  for (const Named& nm : all_models()) {
    SECTION(nm.name) {
      std::vector<double> plastics = {nm.model.initial_plastic()};
      if (nm.model.kind == MaterialKind::Snow) plastics = {1.0, 0.8, 1.5};
      for (double p : plastics)
        for (const Mat3d& F : Fs) check_fd(nm.model, F, p);
    }
  }
  SECTION("fixed corotated and snow through an inverted F") {
    const Mat3d F = random_rotation(rng) * Vec3d(1.2, 1.0, -0.3).asDiagonal() *
                    random_rotation(rng).transpose();
    check_fd(Model::from_desc(desc_fcr()), F, 0.0);
    check_fd(Model::from_desc(desc_snow()), F, 0.9);
  }
}

TEST_CASE("constitutive: Kirchhoff stress equals P F^T and is symmetric", "[constitutive]") {
  std::mt19937 rng(12);
  const std::vector<Mat3d> Fs = test_deformations(rng);
  for (const Named& nm : all_models()) {
    INFO(nm.name);
    const double p = nm.model.kind == MaterialKind::Snow ? 0.85 : nm.model.initial_plastic();
    for (const Mat3d& F : Fs) {
      const Mat3d tau = nm.model.kirchhoff(F, p);
      const Mat3d PFt = nm.model.first_piola(F, p) * F.transpose();
      const double scale = tau.norm() + stress_scale(nm.model);
      CHECK((tau - PFt).norm() < 1e-12 * scale);
      CHECK((tau - tau.transpose()).norm() < 1e-14 * scale);
    }
  }
}

TEST_CASE("constitutive: zero energy and stress at rest", "[constitutive]") {
  const Mat3d I = Mat3d::Identity();
  for (const Named& nm : all_models()) {
    INFO(nm.name);
    std::vector<double> plastics = {nm.model.initial_plastic()};
    if (nm.model.kind == MaterialKind::Snow) plastics = {1.0, 0.7, 3.0};
    for (double p : plastics) {
      CHECK(nm.model.energy(I, p) == 0.0);
      CHECK(nm.model.first_piola(I, p).norm() == 0.0);
      CHECK(nm.model.kirchhoff(I, p).norm() == 0.0);
    }
    // A pure rotation is also at rest.
    std::mt19937 rng(3);
    const Mat3d Q = random_rotation(rng);
    const double p = nm.model.initial_plastic();
    CHECK(std::abs(nm.model.energy(Q, p)) < 1e-9 * stress_scale(nm.model));
    CHECK(nm.model.kirchhoff(Q, p).norm() < 1e-9 * stress_scale(nm.model));
  }
}

TEST_CASE("constitutive: rotation invariance (objectivity)", "[constitutive]") {
  std::mt19937 rng(13);
  const std::vector<Mat3d> Fs = test_deformations(rng);
  for (const Named& nm : all_models()) {
    INFO(nm.name);
    const double p = nm.model.kind == MaterialKind::Snow ? 1.2 : nm.model.initial_plastic();
    for (const Mat3d& F : Fs) {
      const Mat3d Q = random_rotation(rng);
      const double scale = stress_scale(nm.model);
      CHECK(std::abs(nm.model.energy(Q * F, p) - nm.model.energy(F, p)) < 1e-10 * scale);
      const Mat3d tau = nm.model.kirchhoff(F, p);
      CHECK((nm.model.kirchhoff(Q * F, p) - Q * tau * Q.transpose()).norm() < 1e-10 * scale);
      CHECK((nm.model.first_piola(Q * F, p) - Q * nm.model.first_piola(F, p)).norm() <
            1e-10 * scale);
    }
  }
}

TEST_CASE("constitutive: neo-Hookean guards inverted elements", "[constitutive]") {
  const Model nh = Model::from_desc(desc_nh());
  Mat3d F = Mat3d::Identity();
  F(2, 2) = -0.5;  // inverted
  const Mat3d tau = nh.kirchhoff(F, 0.0);
  CHECK(tau.allFinite());
  CHECK(std::isfinite(nh.energy(F, 0.0)));
  CHECK(nh.first_piola(F, 0.0).allFinite());
  // Strong pressure (negative Kirchhoff normal stress) pushes the element back open.
  CHECK(tau.trace() < -10 * nh.lambda);
}

TEST_CASE("constitutive: Drucker-Prager return mapping", "[constitutive]") {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double c : {0.0, 0.01}) {
    const Model sand = Model::from_desc(desc_sand(c));
    const double k = (3 * sand.lambda + 2 * sand.mu) / (2 * sand.mu);
    auto yield = [&](const Vec3d& eps) {  // <= 0 inside the (shifted) cone
      const Vec3d e = (eps.array() - c).matrix();
      const double tr = e.sum();
      return (e.array() - tr / 3).matrix().norm() + k * tr * dp_of(sand).alpha;
    };
    DYNAMIC_SECTION("cohesion " << c
                                << ": projection lands on or inside the cone; inside "
                                   "untouched; expansion to the tip") {
      int n_inside = 0, n_tip = 0, n_cone = 0;
      for (int i = 0; i < 3000; ++i) {
        const Vec3d eps0(0.2 * u(rng) - 0.05, 0.2 * u(rng) - 0.05, 0.2 * u(rng) - 0.05);
        const Mat3d R1 = random_rotation(rng), R2 = random_rotation(rng);
        const Mat3d F0 = R1 * eps0.array().exp().matrix().asDiagonal() * R2.transpose();
        const Vec3d e0 = (hencky(F0).array() - c).matrix();
        Mat3d F = F0;
        double plastic = 0.0;
        sand.project(F, plastic);
        CHECK(plastic == 0.0);
        const Vec3d eps = hencky(F);
        INFO("eps0 = " << eps0.transpose() << ", eps = " << eps.transpose());
        // On or inside the cone, and not on the tension side of the tip.
        CHECK(yield(eps) < 1e-9);
        CHECK((eps.array() - c).sum() < 1e-9);
        if (e0.sum() > 0) {  // expansion: to the tip, F = exp(c) R
          ++n_tip;
          CHECK((F - std::exp(c) * shellmpm::polar3(F0)).norm() < 1e-12);
        } else if (yield(hencky(F0)) <= 0) {  // inside: bit for bit untouched
          ++n_inside;
          CHECK(same_bits(F, F0));
        } else {  // cone: lands on the surface, keeps the trace of the strain
          ++n_cone;
          CHECK(std::abs(yield(eps)) < 1e-9);
          CHECK((eps.array() - c).sum() == Approx(e0.sum()).margin(1e-12));
          // Projection only changes the singular values: same rotation.
          CHECK((shellmpm::polar3(F) - shellmpm::polar3(F0)).norm() < 1e-9);
        }
      }
      // All three cases were exercised.
      CHECK(n_inside > 100);
      CHECK(n_tip > 100);
      CHECK(n_cone > 100);
    }
    DYNAMIC_SECTION("cohesion " << c << ": hydrostatic compression and rest stay put") {
      Mat3d F = 0.9 * Mat3d::Identity();
      const Mat3d F0 = F;
      double plastic = 0.0;
      sand.project(F, plastic);
      CHECK(same_bits(F, F0));
      Mat3d I = Mat3d::Identity();
      sand.project(I, plastic);
      CHECK(same_bits(I, Mat3d::Identity()));
    }
  }
}

TEST_CASE("constitutive: snow return mapping and hardening", "[constitutive]") {
  const Model snow = Model::from_desc(desc_snow());
  const double lo = 1 - snow_of(snow).theta_c, hi = 1 + snow_of(snow).theta_s;
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  SECTION("clamped singular values, J_P J_E preserved, inside untouched") {
    int n_projected = 0, n_inside = 0;
    for (int i = 0; i < 2000; ++i) {
      const Vec3d s0(0.95 + 0.07 * u(rng), 0.95 + 0.07 * u(rng), 0.95 + 0.07 * u(rng));
      const Mat3d F0 = random_rotation(rng) * s0.asDiagonal() * random_rotation(rng).transpose();
      const double jp0 = 0.8 + 0.4 * u(rng);
      Mat3d F = F0;
      double jp = jp0;
      snow.project(F, jp);
      Mat3d U, V;
      Vec3d s;
      shellmpm::svd3(F, U, s, V);
      INFO("sigma0 = " << s0.transpose() << ", sigma = " << s.transpose());
      CHECK(s.minCoeff() >= lo - 1e-12);
      CHECK(s.maxCoeff() <= hi + 1e-12);
      const bool inside = s0.minCoeff() >= lo && s0.maxCoeff() <= hi;
      if (inside) {
        ++n_inside;
        CHECK(same_bits(F, F0));
        CHECK(jp == jp0);
      } else {
        ++n_projected;
        CHECK(jp * F.determinant() == Approx(jp0 * F0.determinant()).epsilon(1e-12));
        CHECK(jp != jp0);
      }
    }
    CHECK(n_inside > 50);
    CHECK(n_projected > 50);
  }
  SECTION("J_P clamped to its bounds; inverted F_E counts as full compression") {
    Mat3d F = 0.5 * Mat3d::Identity();  // strong compression: J_P drops
    double jp = 0.61;
    snow.project(F, jp);
    CHECK(jp == snow_of(snow).jp_min);
    F = 1.5 * Mat3d::Identity();  // strong stretch: J_P grows
    jp = 19.0;
    snow.project(F, jp);
    CHECK(jp == snow_of(snow).jp_max);
    F = Mat3d::Identity();
    F(0, 0) = -1.0;
    jp = 1.0;
    snow.project(F, jp);
    CHECK(jp == snow_of(snow).jp_min);
    CHECK(F.determinant() > 0);
  }
  SECTION("hardening scales energy, stress and wave speed") {
    const Mat3d F = random_rotation(rng) * Vec3d(1.01, 0.98, 0.99).asDiagonal();
    for (double jp : {0.7, 1.0, 1.3}) {
      const double h = std::exp(snow_of(snow).xi * (1 - jp));
      CHECK(snow.hardening(jp) == Approx(h));
      CHECK(snow.energy(F, jp) == Approx(h * snow.energy(F, 1.0)).epsilon(1e-12));
      CHECK((snow.kirchhoff(F, jp) - h * snow.kirchhoff(F, 1.0)).norm() <
            1e-10 * snow.kirchhoff(F, jp).norm());
      CHECK(snow.wave_speed(400.0, jp) ==
            Approx(std::sqrt(h * (snow.lambda + 2 * snow.mu) / 400.0)));
    }
  }
}

TEST_CASE("constitutive: wave speed", "[constitutive]") {
  for (const Named& nm : all_models()) {
    if (nm.model.kind == MaterialKind::Snow) continue;
    CHECK(nm.model.wave_speed(1000.0, nm.model.initial_plastic()) ==
          Approx(std::sqrt((nm.model.lambda + 2 * nm.model.mu) / 1000.0)));
  }
}

TEMPLATE_TEST_CASE("constitutive: batch calls match per-particle calls", "[constitutive]", float,
                   double) {
  using T = TestType;
  using M = ConstitutiveModelT<T>;
  using Mat3T = typename M::Mat3T;
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::size_t n = 37;  // not a multiple of any batch width
  std::vector<Mat3T> F(n);
  for (auto& f : F)
    f = (random_rotation(rng) *
         Vec3d(0.9 + 0.2 * u(rng), 0.9 + 0.2 * u(rng), 0.9 + 0.2 * u(rng)).asDiagonal() *
         random_rotation(rng).transpose())
            .cast<T>();
  const double tol = std::is_same<T, float>::value ? 1e-4 : 1e-11;
  for (const MaterialDesc& d :
       {desc_fcr(), desc_nh(), desc_sand(0.0), desc_sand(0.01), desc_snow()}) {
    INFO(d.name);
    const M m = M::from_desc(d);
    std::vector<T> jp(n, m.initial_plastic());
    const double scale = m.mu + m.lambda;
    std::vector<Mat3T> tau(n);
    m.kirchhoff_batch(F.data(), jp.data(), tau.data(), n);
    for (std::size_t i = 0; i < n; ++i)
      CHECK((tau[i] - m.kirchhoff(F[i], jp[i])).template cast<double>().norm() < tol * scale);

    std::vector<Mat3T> Fb = F, Fs = F, Fc = F;
    std::vector<T> jb = jp, js = jp, jc = jp;
    m.project_batch(Fb.data(), jb.data(), n);
    std::vector<Mat3T> tau_c(n);
    m.project_and_kirchhoff_batch(Fc.data(), jc.data(), tau_c.data(), n);
    for (std::size_t i = 0; i < n; ++i) {
      m.project(Fs[i], js[i]);
      CHECK((Fb[i] - Fs[i]).template cast<double>().norm() < tol);
      CHECK(double(std::abs(jb[i] - js[i])) < tol);
      CHECK((Fc[i] - Fs[i]).template cast<double>().norm() < tol);
      CHECK((tau_c[i] - m.kirchhoff(Fs[i], js[i])).template cast<double>().norm() < tol * scale);
      // Per-particle combined call agrees too.
      Mat3T Fp = F[i];
      T jpp = jp[i];
      const Mat3T tp = m.project_and_kirchhoff(Fp, jpp);
      CHECK((Fp - Fs[i]).template cast<double>().norm() < tol);
      CHECK((tp - m.kirchhoff(Fs[i], js[i])).template cast<double>().norm() < tol * scale);
      // Untouched particles are bit for bit untouched in the batch as well.
      if (std::memcmp(Fs[i].data(), F[i].data(), sizeof(T) * 9) == 0)
        CHECK(std::memcmp(Fb[i].data(), F[i].data(), sizeof(T) * 9) == 0);
    }
  }
}

TEST_CASE("constitutive: float instantiation agrees with double", "[constitutive]") {
  using Mf = ConstitutiveModelT<float>;
  std::mt19937 rng(51);
  for (const MaterialDesc& d : {desc_fcr(), desc_nh(), desc_sand(0.01), desc_snow()}) {
    INFO(d.name);
    const Model md = Model::from_desc(d);
    const Mf mf = Mf::from_desc(d);
    const double scale = md.mu + md.lambda;
    for (int i = 0; i < 50; ++i) {
      const Mat3d F = random_rotation(rng) * (Mat3d::Identity() + random_matrix(rng, 0.1));
      const Eigen::Matrix3f Ff = F.cast<float>();
      const double p = md.kind == MaterialKind::Snow ? 1.1 : 0.0;
      const Mat3d Fr = Ff.cast<double>();  // same input for both
      CHECK(std::abs(mf.energy(Ff, float(p)) - md.energy(Fr, p)) < 1e-4 * scale);
      CHECK((mf.kirchhoff(Ff, float(p)).cast<double>() - md.kirchhoff(Fr, p)).norm() <
            1e-4 * scale);
      CHECK((mf.first_piola(Ff, float(p)).cast<double>() - md.first_piola(Fr, p)).norm() <
            1e-4 * scale);
      Mat3d Fd = Fr;
      double pd = p;
      Eigen::Matrix3f Fpf = Ff;
      float pf = float(p);
      md.project(Fd, pd);
      mf.project(Fpf, pf);
      CHECK((Fpf.cast<double>() - Fd).norm() < 1e-5);
      CHECK(std::abs(double(pf) - pd) < 1e-4);
    }
  }
}

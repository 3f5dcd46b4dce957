// Tests of sim/math/svd3.h: reconstruction, orthonormality, det +1, ordering and signs,
// agreement with Eigen::JacobiSVD, on random, inverted, rank-deficient, repeated,
// clustered, rotation and diagonal matrices; batch == scalar; polar decomposition.
#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "sim/math/svd3.h"

namespace {

using shellmpm::polar3;
using shellmpm::svd3;
using shellmpm::svd3_batch;
using Mat3d = Eigen::Matrix3d;

template <class T>
using M3 = Eigen::Matrix<T, 3, 3>;
template <class T>
using V3 = Eigen::Matrix<T, 3, 1>;

Mat3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

/// A labelled family of test matrices (in double; cast to T by the caller).
struct Case {
  std::string label;
  Mat3d A;
};

std::vector<Case> make_cases(int per_kind, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto rnd = [&]() { return Mat3d(Mat3d::NullaryExpr([&]() { return u(rng); })); };
  auto usv = [&](double s0, double s1, double s2) {
    return Mat3d(random_rotation(rng) * Eigen::Vector3d(s0, s1, s2).asDiagonal() *
                 random_rotation(rng).transpose());
  };
  std::vector<Case> out;
  for (int i = 0; i < per_kind; ++i) {
    const double scale = std::pow(10.0, 2.0 * u(rng));  // 1e-2 .. 1e2
    auto add = [&](const char* label, const Mat3d& A) { out.push_back({label, scale * A}); };
    add("random", rnd());
    Mat3d inv = rnd();
    if (inv.determinant() > 0) inv.col(0) = -inv.col(0);
    add("inverted random", inv);
    add("repeated (1,1,1)", usv(1, 1, 1));
    add("repeated (2,2,0.5)", usv(2, 2, 0.5));
    add("repeated inverted (1.5,1.5,-1.5)", usv(1.5, 1.5, -1.5));
    add("clustered (1,1+1e-7,1e-3)", usv(1, 1 + 1e-7 * u(rng), 1e-3));
    add("clustered small (1,1e-4,1e-4)", usv(1, 1e-4, 1e-4 * (1 + 1e-6 * u(rng))));
    add("clustered triple", usv(1 + 1e-3 * u(rng), 1 + 1e-3 * u(rng), 1 + 1e-3 * u(rng)));
    add("rank 2", usv(1, 0.5, 0));
    add("rank 1", usv(1, 0, 0));
    add("graded inverted (2,1e-3,-1e-6)", usv(2, 1e-3, -1e-6));
    add("near identity", Mat3d(Mat3d::Identity() + 1e-6 * rnd()));
    add("stretched rotation", Mat3d(random_rotation(rng) * (Mat3d::Identity() + 0.3 * rnd())));
    add("rotation", random_rotation(rng));
    add("diagonal", Mat3d(Eigen::Vector3d(u(rng), u(rng), u(rng)).asDiagonal()));
  }
  Mat3d P;
  P << 0, 1, 0, 0, 0, 1, 1, 0, 0;
  out.push_back({"permutation (even)", P});
  Mat3d Q;
  Q << 0, 1, 0, 1, 0, 0, 0, 0, 1;
  out.push_back({"permutation (odd)", Q});
  out.push_back({"zero", Mat3d::Zero()});
  out.push_back({"identity", Mat3d::Identity()});
  out.push_back({"minus identity", Mat3d(-Mat3d::Identity())});
  out.push_back({"diag(-2,3,0.5)", Mat3d(Eigen::Vector3d(-2, 3, 0.5).asDiagonal())});
  out.push_back({"diag(0,0,-1)", Mat3d(Eigen::Vector3d(0, 0, -1).asDiagonal())});
  out.push_back({"tiny", Mat3d(1e-30 * Mat3d::Identity() + 1e-31 * Mat3d::Ones())});
  out.push_back({"huge", Mat3d(1e30 * Mat3d::Identity() + 1e29 * Mat3d::Ones())});
  return out;
}

/// Worst errors over a set of decompositions, all relative to sigma_max of the input.
struct Worst {
  double recon = 0, orth = 0, det = 0, sv = 0, order = 0;
  int sign_errors = 0, nonfinite = 0;
  std::string where;
  void update(double& slot, double v, const std::string& label) {
    if (v > slot) {
      slot = v;
      where = label;
    }
  }
};

template <class T>
void check_one(const Case& c, const M3<T>& A, const M3<T>& U, const V3<T>& s, const M3<T>& V,
               Worst& w) {
  const Mat3d Ad = A.template cast<double>(), Ud = U.template cast<double>(),
              Vd = V.template cast<double>();
  const Eigen::Vector3d sd = s.template cast<double>();
  if (!Ud.allFinite() || !Vd.allFinite() || !sd.allFinite()) {
    ++w.nonfinite;
    w.where = c.label;
    return;
  }
  const Eigen::Vector3d ref = Eigen::JacobiSVD<Mat3d>(Ad).singularValues();
  const double smax = std::max(ref(0), std::numeric_limits<double>::min());
  w.update(w.recon, (Ud * sd.asDiagonal() * Vd.transpose() - Ad).norm() / smax, c.label);
  w.update(w.orth,
           std::max((Ud.transpose() * Ud - Mat3d::Identity()).norm(),
                    (Vd.transpose() * Vd - Mat3d::Identity()).norm()),
           c.label);
  w.update(w.det, std::max(std::abs(Ud.determinant() - 1), std::abs(Vd.determinant() - 1)),
           c.label);
  double sv = 0;
  for (int k = 0; k < 3; ++k) sv = std::max(sv, std::abs(std::abs(sd(k)) - ref(k)) / smax);
  w.update(w.sv, sv, c.label);
  const double order = std::max(0.0, std::abs(sd(1)) - std::abs(sd(0))) +
                       std::max(0.0, std::abs(sd(2)) - std::abs(sd(1)));
  w.update(w.order, order / smax, c.label);
  const double detA = Ad.determinant();
  bool sign_ok = sd(0) >= 0 && sd(1) >= 0;
  if (std::abs(detA) > 1e-3 * smax * smax * smax) sign_ok = sign_ok && ((sd(2) < 0) == (detA < 0));
  if (!sign_ok) {
    ++w.sign_errors;
    w.where = c.label;
  }
}

template <class T>
void require_worst(const Worst& w) {
  const double eps = std::numeric_limits<T>::epsilon();
  const double tol = 64 * eps;
  INFO("worst case family: " << w.where << "; recon " << w.recon << ", orth " << w.orth << ", det "
                             << w.det << ", sv " << w.sv << ", order " << w.order << " (tol " << tol
                             << ")");
  CHECK(w.nonfinite == 0);
  CHECK(w.sign_errors == 0);
  CHECK(w.recon < tol);
  CHECK(w.orth < tol);
  CHECK(w.det < tol);
  CHECK(w.sv < tol);
  CHECK(w.order < tol);
}

}  // namespace

TEMPLATE_TEST_CASE("svd3: reconstruction, rotations, ordering, signs, vs JacobiSVD", "[svd]", float,
                   double) {
  using T = TestType;
  const auto cases = make_cases(1500, 17u);
  Worst w;
  for (const Case& c : cases) {
    const M3<T> A = c.A.cast<T>();
    M3<T> U, V;
    V3<T> s;
    svd3(A, U, s, V);
    check_one<T>(c, A, U, s, V, w);
  }
  require_worst<T>(w);
}

TEMPLATE_TEST_CASE("svd3: exact on identity, zero and diagonal inputs", "[svd]", float, double) {
  using T = TestType;
  M3<T> U, V;
  V3<T> s;
  svd3(M3<T>(M3<T>::Identity()), U, s, V);
  CHECK(U == M3<T>::Identity());
  CHECK(V == M3<T>::Identity());
  CHECK(s == V3<T>::Ones());

  svd3(M3<T>(M3<T>::Zero()), U, s, V);
  CHECK(s == V3<T>::Zero());
  CHECK((U.transpose() * U - M3<T>::Identity()).norm() < 1e-6);
  CHECK(std::abs(U.determinant() - T(1)) < 1e-6);
  CHECK(std::abs(V.determinant() - T(1)) < 1e-6);

  // diag(-2, 3, 0.5): det < 0, so sigma = (3, 2, -0.5).
  svd3(M3<T>(V3<T>(-2, 3, 0.5).asDiagonal()), U, s, V);
  CHECK(s(0) == Approx(3).epsilon(1e-6));
  CHECK(s(1) == Approx(2).epsilon(1e-6));
  CHECK(s(2) == Approx(-0.5).epsilon(1e-6));
}

TEMPLATE_TEST_CASE("svd3_batch matches svd3, any length, optional outputs", "[svd]", float,
                   double) {
  using T = TestType;
  const auto cases = make_cases(300, 23u);
  std::vector<M3<T>> A;
  for (const Case& c : cases) A.push_back(c.A.cast<T>());
  const std::size_t W = shellmpm::svd3_batch_width<T>();
  const std::size_t n = (A.size() / W) * W - 1;  // not a multiple of the batch width
  REQUIRE((W == 1 || n % W != 0));
  std::vector<M3<T>> U(n), V(n);
  std::vector<V3<T>> s(n);
  svd3_batch(A.data(), n, U.data(), s.data(), V.data());
  Worst w;
  double max_sigma_diff = 0;
  for (std::size_t i = 0; i < n; ++i) {
    check_one<T>(cases[i], A[i], U[i], s[i], V[i], w);
    M3<T> U1, V1;
    V3<T> s1;
    svd3(A[i], U1, s1, V1);
    const double smax = std::max<double>(std::abs(s1(0)), std::numeric_limits<T>::min());
    max_sigma_diff = std::max(max_sigma_diff, double((s1 - s[i]).norm()) / smax);
  }
  require_worst<T>(w);
  CHECK(max_sigma_diff < 64 * std::numeric_limits<T>::epsilon());

  // Only sigma requested.
  std::vector<V3<T>> s2(n);
  svd3_batch<T>(A.data(), n, nullptr, s2.data(), nullptr);
  for (std::size_t i = 0; i < n; ++i) CHECK(s2[i] == s[i]);
  // Empty input is a no-op.
  svd3_batch<T>(A.data(), 0, nullptr, nullptr, nullptr);
}

TEMPLATE_TEST_CASE("polar3: proper rotation, symmetric factor, matches SVD-based polar", "[svd]",
                   float, double) {
  using T = TestType;
  const double tol = 64 * std::numeric_limits<T>::epsilon();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 500; ++i) {
    Mat3d Ad = random_rotation(rng) *
               (Mat3d::Identity() + 0.4 * Mat3d(Mat3d::NullaryExpr([&]() { return u(rng); })));
    if (i % 2) Ad.col(1) = -Ad.col(1);  // half of them inverted
    const M3<T> A = Ad.cast<T>();
    M3<T> R, S;
    polar3(A, R, S);
    const Mat3d Rd = R.template cast<double>(), Sd = S.template cast<double>();
    const double n = Ad.norm();
    CHECK((Rd * Sd - Ad).norm() < tol * n);
    CHECK((Sd - Sd.transpose()).norm() < tol * n);
    CHECK((Rd.transpose() * Rd - Mat3d::Identity()).norm() < tol);
    CHECK(std::abs(Rd.determinant() - 1) < tol);
    CHECK((polar3(A).template cast<double>() - Rd).norm() < tol);
    // S is positive definite iff A is not inverted.
    const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Mat3d>(Sd).eigenvalues();
    if (std::abs(Ad.determinant()) > 1e-2) CHECK((ev.minCoeff() > 0) == (Ad.determinant() > 0));
    if (Ad.determinant() > 0) {  // the unique polar factor
      Eigen::JacobiSVD<Mat3d> svd(Ad, Eigen::ComputeFullU | Eigen::ComputeFullV);
      const Mat3d Rref = svd.matrixU() * svd.matrixV().transpose();
      CHECK((Rd - Rref).norm() < 1e3 * tol);
    }
  }
  // A rotation is its own polar factor.
  const Mat3d Q = random_rotation(rng);
  CHECK((polar3(M3<T>(Q.cast<T>())).template cast<double>() - Q).norm() < tol);
}

// The quasi-definite factor (sim/implicit/symmetric_factor.h) against dense solves.
#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "sim/implicit/symmetric_factor.h"

using namespace shellmpm;

namespace {

/// [S I; I -K] of two m x m blocks: S a shifted graph Laplacian coupling i to i + 1 and
/// i + 7 (positive definite), K a stiffer one coupling i to i + 1 with a zero row at
/// `soft` (semi-definite: the tiny shift keeps the whole quasi-definite). `scale` changes
/// the values, not the pattern.
SparseMatrixD quasi_definite(int m, double scale, int soft = -1) {
  std::vector<Eigen::Triplet<double>> t;
  const auto couple = [&](int off, int i, int j, double w, double sign) {
    t.emplace_back(off + i, off + i, sign * w);
    t.emplace_back(off + j, off + j, sign * w);
    t.emplace_back(off + i, off + j, -sign * w);
    t.emplace_back(off + j, off + i, -sign * w);
  };
  for (int i = 0; i < m; ++i) {
    t.emplace_back(i, i, 0.5 + 0.01 * i);
    if (i + 1 < m) couple(0, i, i + 1, 1.0 + 0.1 * (i % 3), 1.0);
    if (i + 7 < m) couple(0, i, i + 7, 0.3 * scale, 1.0);
    t.emplace_back(m + i, m + i, -1e-12);
    if (i + 1 < m && i != soft && i + 1 != soft)
      couple(m, i, i + 1, 1e4 * scale * (1 + i % 4), -1.0);
    t.emplace_back(i, m + i, 1.0);
    t.emplace_back(m + i, i, 1.0);
  }
  SparseMatrixD A(2 * m, 2 * m);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

double relative_error(const SparseMatrixD& A, const Eigen::VectorXd& b, const Eigen::VectorXd& x) {
  const Eigen::VectorXd ref = Eigen::MatrixXd(A).lu().solve(b);
  return (x - ref).norm() / ref.norm();
}

}  // namespace

TEST_CASE("the quasi-definite factor solves as a dense LU does, and reuses its analysis",
          "[symmetric_factor]") {
  const int m = 60;
  SymmetricFactor f;
  const SparseMatrixD A = quasi_definite(m, 1.0);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(2 * m, -1.0, 2.0);
  REQUIRE(f.factorise(A));
  Eigen::VectorXd x;
  f.solve(b, x);
  CHECK(relative_error(A, b, x) < 1e-9);
  CHECK(f.reused() == 0);
  CHECK(f.factor_entries() >= A.nonZeros() / 2);

  // New values on the same pattern: the analysis is reused and the solve follows them.
  const SparseMatrixD B = quasi_definite(m, 3.0);
  REQUIRE(f.factorise(B));
  CHECK(f.reused() == 1);
  f.solve(b, x);
  CHECK(relative_error(B, b, x) < 1e-9);
  CHECK(relative_error(A, b, x) > 1e-3);  // not the old factor

  // A different pattern (a stiffness row gone): analysed again. That row's pivot is the
  // 1e-12 shift alone, which without pivoting costs digits (measured 8e-6): ample for a
  // preconditioner, and grid_shells.cpp drops such rows before it factorises.
  const SparseMatrixD C = quasi_definite(m, 1.0, 20);
  REQUIRE(C.nonZeros() < A.nonZeros());
  REQUIRE(f.factorise(C));
  CHECK(f.reused() == 1);
  f.solve(b, x);
  CHECK(relative_error(C, b, x) < 1e-4);
}

TEST_CASE("the quasi-definite factor refuses a matrix it cannot factorise", "[symmetric_factor]") {
  SymmetricFactor f;
  SparseMatrixD A = quasi_definite(10, 1.0);
  A.coeffRef(3, 3) = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(f.factorise(A));
  SparseMatrixD empty(0, 0);
  CHECK_FALSE(f.factorise(empty));
  // And works again afterwards.
  const SparseMatrixD B = quasi_definite(10, 1.0);
  REQUIRE(f.factorise(B));
  Eigen::VectorXd x;
  f.solve(Eigen::VectorXd::Ones(20), x);
  CHECK(relative_error(B, Eigen::VectorXd::Ones(20), x) < 1e-9);
}

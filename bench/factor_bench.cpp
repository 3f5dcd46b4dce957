// bench/factor_bench: the implicit grid step's quasi-definite factor (the shells' exact
// coupling, sim/implicit/grid_shells.h) by MUMPS (sim/implicit/symmetric_factor.h) against
// Eigen's simplicial LDL^T in the same (AMD) order: seconds to factorise and to solve, and
// the factor's size, and the solve's backward error |A x - b| / (|A| |x|).
//
// The system is built as grid_shells.cpp builds it, on a flat sheet of n x n square
// elements whose spacing is the grid's cell: its control points ((n + 1)^2) and two
// contact particles per element (one per triangle) are the joint unknowns, 3 each; J holds
// their quadratic B-spline weights on the grid nodes (times dt), M the nodes' masses from
// the same weights, S = J M^-1 J^T; K couples unknowns within 2.5 cells (a Loop patch's
// reach) with stiff springs, plus 1% of their stiffness on the diagonal (pins, contact).
// A = [S + eps I, I; I, -(K + eps I)]. n = 15 matches the
// steel dent (2,118 joint unknowns against its 1,938 with stiffness) and n = 40 cloth_drape
// (14,643, as its 1,681 control points and 3,200 contact particles).
//
//   factor_bench [--sizes 15,40] [--repeat 3]
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "bench/bench_args.h"
#include "sim/implicit/symmetric_factor.h"

using namespace shellmpm;

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Quadratic B-spline weights of coordinate x (in cells) on base, base + 1, base + 2.
void weights(double x, int& base, double w[3]) {
  base = static_cast<int>(std::floor(x - 0.5));
  const double f = x - base;
  w[0] = 0.5 * (1.5 - f) * (1.5 - f);
  w[1] = 0.75 - (f - 1) * (f - 1);
  w[2] = 0.5 * (f - 0.5) * (f - 0.5);
}

SparseMatrixD sheet_system(int n, int& m) {
  std::vector<Eigen::Vector2d> sites;  // in-plane positions [cells]
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) sites.emplace_back(i + 0.2, j + 0.2);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      sites.emplace_back(i + 0.2 + 1.0 / 3, j + 0.2 + 1.0 / 3);
      sites.emplace_back(i + 0.2 + 2.0 / 3, j + 0.2 + 2.0 / 3);
    }
  const int ns = static_cast<int>(sites.size());
  m = 3 * ns;
  const double dt = 1e-3, y = 0.3;  // the sheet's height within its cell layer
  std::map<std::array<int, 3>, int> node_of;
  std::vector<Eigen::Triplet<double>> tj;
  std::vector<double> mass;
  for (int s = 0; s < ns; ++s) {
    int b[3];
    double w[3][3];
    weights(sites[s].x(), b[0], w[0]);
    weights(y + 1.0, b[1], w[1]);
    weights(sites[s].y(), b[2], w[2]);
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c)
        for (int d = 0; d < 3; ++d) {
          const std::array<int, 3> key = {b[0] + a, b[1] + c, b[2] + d};
          auto it = node_of.find(key);
          if (it == node_of.end()) {
            it = node_of.emplace(key, static_cast<int>(mass.size())).first;
            mass.push_back(0);
          }
          const double wt = w[0][a] * w[1][c] * w[2][d];
          mass[static_cast<std::size_t>(it->second)] += wt;
          for (int k = 0; k < 3; ++k) tj.emplace_back(3 * s + k, 3 * it->second + k, dt * wt);
        }
  }
  const int nn = static_cast<int>(mass.size());
  SparseMatrixD J(m, 3 * nn), Minv(3 * nn, 3 * nn);
  J.setFromTriplets(tj.begin(), tj.end());
  std::vector<Eigen::Triplet<double>> tm;
  for (int i = 0; i < nn; ++i)
    for (int k = 0; k < 3; ++k) tm.emplace_back(3 * i + k, 3 * i + k, 1.0 / mass[i]);
  Minv.setFromTriplets(tm.begin(), tm.end());
  const SparseMatrixD S = (J * Minv * SparseMatrixD(J.transpose())).pruned();
  // K: springs between unknowns within 2.5 cells, stiff against S.
  std::vector<Eigen::Triplet<double>> t;
  double smax = S.diagonal().maxCoeff();
  const double k0 = 1e4 / smax, eps = 1e-12;
  for (int a = 0; a < ns; ++a)
    for (int b = a + 1; b < ns; ++b) {
      const double d = (sites[a] - sites[b]).norm();
      if (d > 2.5) continue;
      const double k = k0 / (0.5 + d);
      for (int c = 0; c < 3; ++c) {
        const int i = m + 3 * a + c, j = m + 3 * b + c;
        t.emplace_back(i, i, -k);
        t.emplace_back(j, j, -k);
        t.emplace_back(i, j, k);
        t.emplace_back(j, i, k);
      }
    }
  for (Eigen::Index col = 0; col < S.outerSize(); ++col)
    for (SparseMatrixD::InnerIterator it(S, col); it; ++it)
      t.emplace_back(static_cast<int>(it.row()), static_cast<int>(col), it.value());
  for (int i = 0; i < m; ++i) {
    t.emplace_back(i, i, eps * smax);
    t.emplace_back(m + i, m + i, -(eps + 1e-2) * k0);  // pins, contact: K definite
    t.emplace_back(i, m + i, 1.0);
    t.emplace_back(m + i, i, 1.0);
  }
  SparseMatrixD A(2 * m, 2 * m);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes = {15, 40};
  int repeat = 3;
  if (!shellmpm_bench::parse_options(
          argc, argv,
          {{"--sizes", [&](const char* v) { sizes = shellmpm_bench::parse_int_list(v); }},
           {"--repeat", [&](const char* v) { repeat = std::max(1, std::atoi(v)); }}}))
    return 2;
  std::printf("quasi-definite [S I; I -K] of a sheet on the grid, one thread, best of %d:\n",
              repeat);
  for (const int n : sizes) {
    int m = 0;
    const SparseMatrixD A = sheet_system(n, m);
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 1.0);
    double e_fact = 1e30, e_solve = 1e30, m_first = 1e30, m_fact = 1e30, m_solve = 1e30;
    double e_res = 0, m_res = 0;
    long e_entries = 0, m_entries = 0;
    for (int r = 0; r < repeat; ++r) {
      SparseLdlt eigen;
      eigen.analyzePattern(A);
      auto t0 = Clock::now();
      eigen.factorize(A);
      e_fact = std::min(e_fact, since(t0));
      t0 = Clock::now();
      const Eigen::VectorXd xe = eigen.solve(b);
      e_solve = std::min(e_solve, since(t0));
      e_res = (A * xe - b).norm() / (A.norm() * xe.norm());
      e_entries = static_cast<long>(eigen.matrixL().nestedExpression().nonZeros());

      SymmetricFactor mumps;
      t0 = Clock::now();
      if (!mumps.factorise(A)) {
        std::printf("  n %d: MUMPS failed\n", n);
        return 1;
      }
      m_first = std::min(m_first, since(t0));
      t0 = Clock::now();
      mumps.factorise(A);  // the same pattern: the analysis is reused
      m_fact = std::min(m_fact, since(t0));
      Eigen::VectorXd xm;
      t0 = Clock::now();
      mumps.solve(b, xm);
      m_solve = std::min(m_solve, since(t0));
      m_res = (A * xm - b).norm() / (A.norm() * xm.norm());
      m_entries = mumps.factor_entries();
    }
    std::printf(
        "  %2d x %2d elements, %5d joint unknowns (%d rows, %ld entries):\n"
        "    Eigen simplicial LDL^T: factor %7.3f s, solve %6.4f s, %9ld factor entries, "
        "backward error %.0e\n"
        "    MUMPS:                  factor %7.3f s (%7.3f s with the analysis), solve "
        "%6.4f s, %9ld factor entries, backward error %.0e\n",
        n, n, m, 2 * m, static_cast<long>(A.nonZeros()), e_fact, e_solve, e_entries, e_res, m_fact,
        m_first, m_solve, m_entries, m_res);
  }
  return 0;
}

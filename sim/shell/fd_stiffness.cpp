#include "sim/shell/fd_stiffness.h"

#include <algorithm>
#include <cmath>

#include "sim/core/check.h"

namespace shellmpm {

std::vector<std::vector<int>> colour_points(const std::vector<std::vector<int>>& coupling,
                                            const std::vector<char>& movable) {
  const int n = static_cast<int>(coupling.size());
  std::vector<int> colour(n, -1), stamp;
  std::vector<std::vector<int>> groups;
  for (int j = 0; j < n; ++j) {
    if (!movable[j]) continue;
    stamp.assign(groups.size() + 1, -1);
    for (int i : coupling[j])
      for (int k : coupling[i])
        if (colour[k] >= 0) stamp[colour[k]] = j;
    int c = 0;
    while (stamp[c] == j) ++c;
    if (c == static_cast<int>(groups.size())) groups.emplace_back();
    colour[j] = c;
    groups[c].push_back(j);
  }
  return groups;
}

SparseMatrixD fd_stiffness(const PointForceFn& forces, const std::vector<Vec3d>& x,
                           const std::vector<Vec3d>& f0, const std::vector<int>& dof_of, int dofs,
                           const std::vector<std::vector<int>>& coupling,
                           const std::vector<std::vector<int>>& groups, double eps) {
  std::vector<Eigen::Triplet<double>> trip;
  std::vector<Vec3d> p, f;
  for (const std::vector<int>& group : groups)
    for (int a = 0; a < 3; ++a) {
      p = x;
      bool any = false;
      for (int j : group)
        if (dof_of[3 * j + a] >= 0) {
          p[j][a] += eps;
          any = true;
        }
      if (!any) continue;
      f.assign(x.size(), Vec3d::Zero());
      forces(p, f);
      for (int j : group) {
        const int col = dof_of[3 * j + a];
        if (col < 0) continue;
        for (int i : coupling[j])
          for (int b = 0; b < 3; ++b) {
            const int row = dof_of[3 * i + b];
            if (row >= 0) trip.emplace_back(row, col, -(f[i][b] - f0[i][b]) / eps);
          }
      }
    }
  SparseMatrixD K(dofs, dofs);
  K.setFromTriplets(trip.begin(), trip.end());
  const SparseMatrixD Kt = K.transpose();
  return 0.5 * (K + Kt);
}

std::unique_ptr<SparseLdlt> factorise_positive(const SparseMatrixD& K) {
  const int n = static_cast<int>(K.rows());
  Eigen::VectorXd diag = K.diagonal().cwiseAbs();
  const double mean = diag.sum() / std::max(n, 1);
  SHELLMPM_CHECK(std::isfinite(mean), << "non-finite stiffness (forces not finite?)");
  auto solver = std::make_unique<SparseLdlt>();
  solver->analyzePattern(K);
  for (double mu = 0;; mu = (mu == 0) ? 1e-8 : 10 * mu) {
    SHELLMPM_CHECK(mu < 1e8, << "stiffness could not be made positive definite");
    SparseMatrixD A = K;
    if (mu > 0)
      for (int i = 0; i < n; ++i) A.coeffRef(i, i) += mu * (diag[i] + mean);
    solver->factorize(A);
    if (solver->info() == Eigen::Success && (solver->vectorD().array() > 0).all()) return solver;
  }
}

}  // namespace shellmpm

// The tangent stiffness of a force field assembled by finite differences, for the shell
// solvers (the static solver's Newton steps, the implicit step's preconditioner). Many
// points are perturbed at once: a distance-2 colouring of the coupling graph (Curtis,
// Powell & Reid 1974) puts points whose coupling sets are disjoint in one group, so one
// force evaluation per group and axis separates their stiffness columns.
#pragma once
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <functional>
#include <memory>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

using SparseMatrixD = Eigen::SparseMatrix<double>;
using SparseLdlt = Eigen::SimplicialLDLT<SparseMatrixD>;
/// Full force vector at positions p into f (sized to p and zeroed by the caller).
using PointForceFn = std::function<void(const std::vector<Vec3d>&, std::vector<Vec3d>&)>;

/// Greedy distance-2 colouring of the points with movable[j] set: points sharing a
/// colour have disjoint coupling sets. coupling[j] lists every point whose force depends
/// on point j (j included).
std::vector<std::vector<int>> colour_points(const std::vector<std::vector<int>>& coupling,
                                            const std::vector<char>& movable);

/// K = -df/dx at x over the numbered degrees of freedom (dof_of[3 i + a]: the row and
/// column of component a of point i, or -1 when it is not one), forward differences of
/// step eps [m], symmetrised. f0 is the force at x.
SparseMatrixD fd_stiffness(const PointForceFn& forces, const std::vector<Vec3d>& x,
                           const std::vector<Vec3d>& f0, const std::vector<int>& dof_of, int dofs,
                           const std::vector<std::vector<int>>& coupling,
                           const std::vector<std::vector<int>>& groups, double eps);

/// Factorises K + mu diag(|K_ii| + mean |K_ii|), raising mu from 0 until the factor is
/// positive definite (so its solve is a descent direction for any gradient).
std::unique_ptr<SparseLdlt> factorise_positive(const SparseMatrixD& K);

}  // namespace shellmpm

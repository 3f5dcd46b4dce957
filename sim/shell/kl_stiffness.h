// The Kirchhoff-Love stiffness as a sparse matrix over numbered degrees of freedom, from
// KirchhoffLoveShellT<double>::stiffness_blocks (per quadrature point Hessians in the
// surface derivatives, not finite differences of the whole force field).
#pragma once
#include <vector>

#include "sim/shell/fd_stiffness.h"
#include "sim/shell/kirchhoff_love.h"

namespace shellmpm {

/// K = d^2E/dx^2 at x over the numbered degrees of freedom (dof_of[3 i + a]: the row and
/// column of component a of control point i, or -1), symmetric. With psd, the sum of each
/// quadrature point's Hessian made positive semi-definite (a preconditioner's K: positive
/// semi-definite however the sheet is compressed).
SparseMatrixD kl_stiffness_matrix(const KirchhoffLoveShellT<double>& kl,
                                  const std::vector<Vec3d>& x, const std::vector<int>& dof_of,
                                  int dofs, bool serial = false, bool psd = false);

}  // namespace shellmpm

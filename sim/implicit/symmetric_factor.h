// A sparse symmetric factorisation for the implicit grid step's preconditioner: the
// quasi-definite system [S I; I -K] of the shells' exact coupling (grid_shells.h).
// MUMPS's multifrontal LDL^T (Debian's libmumps-seq-5.5) without pivoting: a
// quasi-definite matrix (both diagonal blocks definite, here by tiny shifts) has an LDL^T
// for every symmetric ordering (Vanderbei 1995), so the fill-reducing order (AMD) stands
// and the factor's dense fronts go to BLAS-3 kernels. On the steel dent's matrix (3,876
// rows) it takes about 60 ms against 118 ms for Eigen's simplicial LDL^T, on the cloth
// drape's (29,286 rows) 2.2 s against 8.5 s (one thread; docs/implicit.md;
// bench/factor_bench times both on such a system built for a flat sheet).
//
// Independent of the thread count: MUMPS's sequential library runs on the calling thread,
// and its BLAS (OpenBLAS) is held to one thread. Its bits depend on the BLAS kernels
// OpenBLAS picks for the CPU (docs/determinism.md).
#pragma once
#include <memory>
#include <vector>

#include "sim/shell/fd_stiffness.h"

namespace shellmpm {

class SymmetricFactor {
 public:
  SymmetricFactor();
  ~SymmetricFactor();
  SymmetricFactor(const SymmetricFactor&) = delete;
  SymmetricFactor& operator=(const SymmetricFactor&) = delete;

  /// Factorises A (square, symmetric; its lower triangle is read). The symbolic analysis
  /// (ordering, fronts) is kept and reused while A's lower pattern stays the same. Returns
  /// false when MUMPS reports an error or a zero pivot (the factor is then unusable).
  bool factorise(const SparseMatrixD& A);
  /// x = A^-1 b with the last successful factor.
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const;
  /// How many factorisations reused an earlier analysis.
  int reused() const { return reused_; }
  /// Entries in the factor (after factorise).
  long factor_entries() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int reused_ = 0;
};

}  // namespace shellmpm

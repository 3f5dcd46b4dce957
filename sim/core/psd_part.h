// The positive semi-definite part of a small symmetric matrix: its negative eigenvalues
// set to zero. The implicit solves' preconditioners take it of each local Hessian (a
// contact particle's, a Kirchhoff-Love quadrature point's), so their sum is positive
// semi-definite however the local energies are compressed or sheared.
#pragma once
#include <Eigen/Eigenvalues>

namespace shellmpm {

/// H (symmetric) replaced by its positive semi-definite part.
template <int N>
void psd_part(Eigen::Matrix<double, N, N>& H) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> es(H);
  H = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() *
      es.eigenvectors().transpose();
}

}  // namespace shellmpm

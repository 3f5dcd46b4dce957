// Shared pieces of the bulk material models (sim/mpm/materials/): the conventions, and
// small 3x3 helpers on principal values.
//
// Conventions. F is the (elastic) deformation gradient, 3x3, dimensionless. Energies are
// per unit rest volume [Pa = J/m^3]; P = dpsi/dF [Pa]; the Kirchhoff stress is
// tau = P F^T [Pa] (what the MPM grid force needs: f_i = -sum_p V_p^0 tau_p grad w_ip).
// Tension is positive. SVDs are the signed ones of sim/math/svd3.h: F = U diag(sigma) V^T
// with U, V rotations and sigma_2 < 0 for an inverted F. "plastic" is one per-particle
// scalar whose meaning depends on the model (snow: J_P; others: unused, 0).
//
// A model is a struct template on the scalar with its parameters and
//   kUsesSvd, kPlastic          whether it works on singular values, whether it yields
//   initial_plastic(), hardening(plastic)
//   energy, first_piola, kirchhoff, wave_modulus   (of F and the plastic scalar)
// and, when kUsesSvd, principal_kirchhoff(sigma, plastic) and project_sigma(sigma,
// plastic), which the SIMD batches (sim/mpm/constitutive.h) call between batched SVDs.
#pragma once
#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace shellmpm::detail {

/// Cofactor matrix cof(F) = det(F) F^-T, as columns (f1 x f2, f2 x f0, f0 x f1).
template <class T>
inline Eigen::Matrix<T, 3, 3> cofactor3(const Eigen::Matrix<T, 3, 3>& F) {
  Eigen::Matrix<T, 3, 3> C;
  C.col(0) = F.col(1).cross(F.col(2));
  C.col(1) = F.col(2).cross(F.col(0));
  C.col(2) = F.col(0).cross(F.col(1));
  return C;
}

/// U diag(d) U^T, symmetric.
template <class T>
inline Eigen::Matrix<T, 3, 3> rotate_diagonal(const Eigen::Matrix<T, 3, 3>& U,
                                              const Eigen::Matrix<T, 3, 1>& d) {
  Eigen::Matrix<T, 3, 3> R;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      const T v = U(i, 0) * d(0) * U(j, 0) + U(i, 1) * d(1) * U(j, 1) + U(i, 2) * d(2) * U(j, 2);
      R(i, j) = v;
      R(j, i) = v;
    }
  return R;
}

/// Hencky strain log(max(|sigma_i|, s_min)) of the signed singular values.
template <class T>
inline Eigen::Matrix<T, 3, 1> hencky_strain(const Eigen::Matrix<T, 3, 1>& sigma, T s_min) {
  Eigen::Matrix<T, 3, 1> e;
  for (int i = 0; i < 3; ++i) e(i) = std::log(std::max(std::abs(sigma(i)), s_min));
  return e;
}

/// Bounds on the extreme eigenvalues of C = F^T F (the squared singular values of F)
/// without an eigen-solve. With m = tr(C)/3 and D = |C|_F^2 - tr(C)^2/3 (the sum of the
/// squared deviations of the eigenvalues from m), Samuelson's inequality puts every
/// eigenvalue within m -+ sqrt(2 D / 3); the smallest is also >= det(C) / I_2(C), I_2 the
/// second invariant (which bounds the product of the two largest). Exact (1, 1) for a
/// rotation; the upper bound is exact for uniaxial stretch. Returns sigma_max^2 >= its
/// bound; *lo (optional) gets a lower bound on sigma_min^2 (possibly 0).
template <class T>
inline T squared_stretch_bounds(const Eigen::Matrix<T, 3, 3>& F, T* lo = nullptr) {
  const T c00 = F.col(0).squaredNorm(), c11 = F.col(1).squaredNorm(), c22 = F.col(2).squaredNorm();
  const T c01 = F.col(0).dot(F.col(1)), c02 = F.col(0).dot(F.col(2)), c12 = F.col(1).dot(F.col(2));
  const T tr = c00 + c11 + c22;
  const T c2 = c00 * c00 + c11 * c11 + c22 * c22 + T(2) * (c01 * c01 + c02 * c02 + c12 * c12);
  const T m = tr / T(3);
  const T r = std::sqrt(std::max(c2 - tr * m, T(0)) * (T(2) / T(3)));
  if (lo) {
    const T i2 = (tr * tr - c2) / T(2);
    const T J = F.determinant();
    *lo = std::max(m - r, i2 > T(0) ? J * J / i2 : T(0));
  }
  return m + r;
}

}  // namespace shellmpm::detail

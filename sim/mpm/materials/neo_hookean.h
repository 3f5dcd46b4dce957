// Compressible neo-Hookean elasticity (as in Bonet & Wood, "Nonlinear Continuum
// Mechanics for Finite Element Analysis", ch. 6, written for F):
//   psi = mu/2 (tr(F^T F) - 3) - mu log J + lambda/2 (log J)^2
//   P   = mu (F - F^-T) + lambda log J F^-T
//   tau = mu (F F^T - I) + lambda log J I          (no SVD, no inverse)
// log J is undefined for J <= 0 (inverted elements). J is clamped to kMinJ inside the
// logarithms (energy and stresses alike): the pressure lambda log J_c then stays large
// and finite and pushes the element back out. Below kMinJ the energy and P are a
// regularization and no longer each other's derivative.
#pragma once
#include "sim/mpm/materials/material_math.h"

namespace shellmpm {

template <class T>
struct NeoHookeanT {
  using Mat3T = Eigen::Matrix<T, 3, 3>;
  using Vec3T = Eigen::Matrix<T, 3, 1>;
  static constexpr bool kUsesSvd = false;
  static constexpr bool kPlastic = false;
  /// J below this is clamped inside the logarithms.
  static constexpr T kMinJ = T(1e-6);
  T mu = T(0), lambda = T(0);  ///< Lame parameters [Pa]

  T initial_plastic() const { return T(0); }
  T hardening(T) const { return T(1); }
  T energy(const Mat3T& F, T) const {
    const T lj = std::log(std::max(F.determinant(), kMinJ));
    return mu / T(2) * (F.squaredNorm() - T(3)) - mu * lj + lambda / T(2) * lj * lj;
  }
  Mat3T first_piola(const Mat3T& F, T) const {
    // P = mu F + (lambda log J_c - mu) cof(F) / J_c; exact for J > kMinJ.
    const T Jc = std::max(F.determinant(), kMinJ);
    return mu * F + ((lambda * std::log(Jc) - mu) / Jc) * detail::cofactor3(F);
  }
  Mat3T kirchhoff(const Mat3T& F, T) const {
    // tau = mu (F F^T - I) + lambda log J_c I.
    const T lj = std::log(std::max(F.determinant(), kMinJ));
    Mat3T tau = mu * (F * F.transpose());
    tau.diagonal().array() += lambda * lj - mu;
    return tau;
  }
  /// rho0 c^2 bound: tau_i = mu (sigma_i^2 - 1) + lambda log J_c gives
  /// mu (sigma_max^2 + 1) + lambda (1 - log J_c).
  T wave_modulus(const Mat3T& F, T) const {
    const T s2_max = detail::squared_stretch_bounds(F);
    const T J = F.determinant();
    const T lj = std::log(std::max(J, kMinJ));
    return mu * (s2_max + T(1)) + lambda * (T(1) - lj);
  }
};

}  // namespace shellmpm

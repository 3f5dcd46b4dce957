// Fixed corotated elasticity (Stomakhin, Howes, Schroeder, Teran 2012, "Energetically
// consistent invertible elasticity", SCA; its fixed-corotated energy and first Piola
// stress):
//   psi = mu sum_i (sigma_i - 1)^2 + lambda/2 (J - 1)^2
//   P   = 2 mu (F - R) + lambda (J - 1) J F^-T,   R = U V^T, J F^-T = cof(F)
//   tau = 2 mu (F - R) F^T + lambda (J - 1) J I = U diag(2 mu (sigma_i - 1) sigma_i
//         + lambda (J - 1) J) U^T   (no inverse of F anywhere)
// The same formulas with the moduli scaled by a hardening factor h serve snow (snow.h).
#pragma once
#include "sim/math/svd3.h"
#include "sim/mpm/materials/material_math.h"

namespace shellmpm {
namespace detail {

// Fixed corotated formulas with moduli mu h, lambda h (conventions: material_math.h).
template <class T>
Eigen::Matrix<T, 3, 1> corotated_principal_kirchhoff(T mu, T lambda, T h,
                                                     const Eigen::Matrix<T, 3, 1>& sigma) {
  Eigen::Matrix<T, 3, 1> tau;
  const T m2 = T(2) * mu * h;
  const T J = sigma(0) * sigma(1) * sigma(2);
  const T lj = lambda * h * (J - T(1)) * J;
  for (int i = 0; i < 3; ++i) tau(i) = m2 * (sigma(i) - T(1)) * sigma(i) + lj;
  return tau;
}

template <class T>
T corotated_energy(T mu, T lambda, T h, const Eigen::Matrix<T, 3, 3>& F) {
  Eigen::Matrix<T, 3, 3> U, V;
  Eigen::Matrix<T, 3, 1> sigma;
  svd3(F, U, sigma, V);
  const T J = sigma(0) * sigma(1) * sigma(2);
  return mu * h * (sigma.array() - T(1)).square().sum() +
         lambda * h / T(2) * (J - T(1)) * (J - T(1));
}

template <class T>
Eigen::Matrix<T, 3, 3> corotated_first_piola(T mu, T lambda, T h, const Eigen::Matrix<T, 3, 3>& F) {
  // P = 2 mu (F - R) + lambda (J - 1) cof(F), R = U V^T.
  Eigen::Matrix<T, 3, 3> U, V;
  Eigen::Matrix<T, 3, 1> sigma;
  svd3(F, U, sigma, V);
  const T J = F.determinant();
  return T(2) * mu * h * (F - U * V.transpose()) + lambda * h * (J - T(1)) * cofactor3(F);
}

/// rho0 c^2 bound along any principal direction: h (2 mu sigma_max^2 + lambda J^2).
template <class T>
T corotated_wave_modulus(T mu, T lambda, T h, const Eigen::Matrix<T, 3, 3>& F) {
  const T s2_max = squared_stretch_bounds(F);
  const T J = F.determinant();
  return h * (T(2) * mu * s2_max + lambda * J * J);
}

}  // namespace detail

template <class T>
struct FixedCorotatedT {
  using Mat3T = Eigen::Matrix<T, 3, 3>;
  using Vec3T = Eigen::Matrix<T, 3, 1>;
  static constexpr bool kUsesSvd = true;
  static constexpr bool kPlastic = false;
  T mu = T(0), lambda = T(0);  ///< Lame parameters [Pa]

  T initial_plastic() const { return T(0); }
  T hardening(T) const { return T(1); }
  Vec3T principal_kirchhoff(const Vec3T& sigma, T) const {
    return detail::corotated_principal_kirchhoff(mu, lambda, T(1), sigma);
  }
  bool project_sigma(Vec3T&, T&) const { return false; }
  T energy(const Mat3T& F, T) const { return detail::corotated_energy(mu, lambda, T(1), F); }
  Mat3T first_piola(const Mat3T& F, T) const {
    return detail::corotated_first_piola(mu, lambda, T(1), F);
  }
  T wave_modulus(const Mat3T& F, T) const {
    return detail::corotated_wave_modulus(mu, lambda, T(1), F);
  }
};

}  // namespace shellmpm

// Snow (Stomakhin, Schroeder, Chai, Teran, Selle 2013, "A material point method for snow
// simulation", SIGGRAPH: energy eq. (1) and hardening eq. (2) of its constitutive model,
// and the clamp of the singular values of F_E with F_P absorbing the rest in its
// deformation-gradient update). F holds the elastic part F_E; plastic = J_P, the plastic
// volume ratio (1 at rest).
//   psi = mu(J_P) sum (sigma_i - 1)^2 + lambda(J_P)/2 (J_E - 1)^2   (fixed corotated)
//   mu(J_P) = mu0 exp(xi (1 - J_P)),  lambda(J_P) = lambda0 exp(xi (1 - J_P))
// Return mapping: sigma_i <- clamp(sigma_i, 1 - theta_c, 1 + theta_s),
// J_P <- clamp(J_P prod(sigma_old) / prod(sigma_new), jp_min, jp_max) (keeps J_P J_E,
// i.e. det F, unless a bound on J_P is hit), F_E <- U diag(sigma_new) V^T. An inverted
// F_E (prod(sigma_old) < 0) counts as extreme compression: J_P goes to jp_min.
#pragma once
#include "sim/mpm/materials/fixed_corotated.h"

namespace shellmpm {

template <class T>
struct SnowT {
  using Mat3T = Eigen::Matrix<T, 3, 3>;
  using Vec3T = Eigen::Matrix<T, 3, 1>;
  static constexpr bool kUsesSvd = true;
  static constexpr bool kPlastic = true;
  T mu = T(0), lambda = T(0);        ///< Lame parameters at rest [Pa]
  T theta_c = T(0), theta_s = T(0);  ///< critical compression, stretch
  T xi = T(0);                       ///< hardening coefficient
  T jp_min = T(1), jp_max = T(1);    ///< clamp of J_P

  T initial_plastic() const { return T(1); }
  /// exp(xi (1 - J_P)), the factor on mu and lambda.
  T hardening(T plastic) const { return std::exp(xi * (T(1) - plastic)); }

  Vec3T principal_kirchhoff(const Vec3T& sigma, T plastic) const {
    return detail::corotated_principal_kirchhoff(mu, lambda, hardening(plastic), sigma);
  }

  bool project_sigma(Vec3T& sigma, T& plastic) const {
    const T lo = T(1) - theta_c, hi = T(1) + theta_s;
    if (sigma(0) >= lo && sigma(0) <= hi && sigma(1) >= lo && sigma(1) <= hi && sigma(2) >= lo &&
        sigma(2) <= hi)
      return false;
    const T j_old = sigma(0) * sigma(1) * sigma(2);
    for (int i = 0; i < 3; ++i) sigma(i) = std::min(std::max(sigma(i), lo), hi);
    const T j_new = sigma(0) * sigma(1) * sigma(2);
    const T jp = std::max(plastic * j_old / j_new, T(0));  // inverted F_E -> jp_min
    plastic = std::min(std::max(jp, jp_min), jp_max);
    return true;
  }

  T energy(const Mat3T& F, T plastic) const {
    return detail::corotated_energy(mu, lambda, hardening(plastic), F);
  }
  Mat3T first_piola(const Mat3T& F, T plastic) const {
    return detail::corotated_first_piola(mu, lambda, hardening(plastic), F);
  }
  T wave_modulus(const Mat3T& F, T plastic) const {
    return detail::corotated_wave_modulus(mu, lambda, hardening(plastic), F);
  }
};

}  // namespace shellmpm

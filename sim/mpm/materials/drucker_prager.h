// Sand: Drucker-Prager plasticity on the Hencky strain (Klar, Gast, Pradhana, Fu,
// Schroeder, Jiang, Teran 2016, "Drucker-Prager elastoplasticity for sand animation",
// SIGGRAPH: St. Venant-Kirchhoff energy in the Hencky strain; return mapping of its
// sec. 7, cases I-III):
//   eps = log(Sigma), psi = mu tr(eps^2) + lambda/2 tr(eps)^2
//   tau = U diag(2 mu eps_i + lambda tr(eps)) U^T,   P = tau F^-T = U diag(tau_i /
//         sigma_i) V^T
// Yield in strain space, with the cone tip moved to eps = c (1,1,1) by the cohesion c
// (a Hencky strain): let e = eps - c, e_hat = e - tr(e)/3 (1,1,1) (deviatoric),
// k = (3 lambda + 2 mu) / (2 mu), alpha = sqrt(2/3) 2 sin(phi) / (3 - sin(phi)):
//   case II  (tr(e) > 0, expansion):   eps <- c (1,1,1)            (cone tip)
//   otherwise dgamma = |e_hat| + k tr(e) alpha
//   case I   (dgamma <= 0, inside):    F untouched (bit for bit)
//   case III (dgamma > 0):             eps <- eps - dgamma e_hat / |e_hat|
// then F = U diag(exp(eps)) V^T. The plastic scalar is not used (stays 0): the volume
// correction of Tampubolon et al. 2017 is not applied. For |sigma_i| below kMinSigma
// (10^4-fold compression, or an inverted F where |sigma| is used) the strain is clamped
// at log(kMinSigma); energy and stress stay finite there. A projected inverted F comes
// out non-inverted (exp(eps) > 0), as in common MPM codes.
#pragma once
#include "sim/math/svd3.h"
#include "sim/mpm/materials/material_math.h"

namespace shellmpm {

template <class T>
struct DruckerPragerT {
  using Mat3T = Eigen::Matrix<T, 3, 3>;
  using Vec3T = Eigen::Matrix<T, 3, 1>;
  static constexpr bool kUsesSvd = true;
  static constexpr bool kPlastic = true;
  /// |sigma_i| below this is clamped in the Hencky strain.
  static constexpr T kMinSigma = T(1e-4);
  T mu = T(0), lambda = T(0);  ///< Lame parameters [Pa]
  T alpha = T(0);              ///< Drucker-Prager alpha (dimensionless)
  T cohesion = T(0);           ///< cone tip offset, a Hencky strain (>= 0)

  T initial_plastic() const { return T(0); }
  T hardening(T) const { return T(1); }

  Vec3T principal_kirchhoff(const Vec3T& sigma, T) const {
    Vec3T tau;
    const Vec3T e = detail::hencky_strain(sigma, kMinSigma);
    const T le = lambda * e.sum();
    for (int i = 0; i < 3; ++i) tau(i) = T(2) * mu * e(i) + le;
    return tau;
  }

  bool project_sigma(Vec3T& sigma, T&) const {
    const Vec3T eps = detail::hencky_strain(sigma, kMinSigma);
    const Vec3T e = (eps.array() - cohesion).matrix();
    const T tr = e.sum();
    if (tr > T(0)) {  // case II: expansion, to the (shifted) cone tip
      sigma.setConstant(std::exp(cohesion));
      return true;
    }
    const Vec3T e_hat = (e.array() - tr / T(3)).matrix();
    const T norm = e_hat.norm();
    const T k = (T(3) * lambda + T(2) * mu) / (T(2) * mu);
    const T dgamma = norm + k * tr * alpha;
    if (!(dgamma > T(0))) return false;  // case I: inside the cone, untouched
    // case III: project along the deviatoric direction (norm > 0 here since tr <= 0).
    const Vec3T h = eps - (dgamma / norm) * e_hat;
    for (int i = 0; i < 3; ++i) sigma(i) = std::exp(h(i));
    return true;
  }

  T energy(const Mat3T& F, T) const {
    Mat3T U, V;
    Vec3T sigma;
    svd3(F, U, sigma, V);
    const Vec3T e = detail::hencky_strain(sigma, kMinSigma);
    const T tr = e.sum();
    return mu * e.squaredNorm() + lambda / T(2) * tr * tr;
  }

  Mat3T first_piola(const Mat3T& F, T plastic) const {
    // P = U diag(tau_i / sigma_i) V^T, sigma_i kept away from 0 like the strain.
    Mat3T U, V;
    Vec3T sigma;
    svd3(F, U, sigma, V);
    const Vec3T tau = principal_kirchhoff(sigma, plastic);
    Vec3T d;
    for (int i = 0; i < 3; ++i) {
      const T s = std::max(std::abs(sigma(i)), kMinSigma);
      d(i) = tau(i) / (sigma(i) < T(0) ? -s : s);
    }
    return U * d.asDiagonal() * V.transpose();
  }

  /// rho0 c^2 bound: tau_i = 2 mu e_i + lambda tr(e) gives d tau_i / d e_i - tau_i <=
  /// lambda + 2 mu - tau_i (equal where sigma_i is not clamped); e_i >= log sigma_min,
  /// tr(e) >= log |J|: lambda + 2 mu - 2 mu log sigma_min - lambda log |J| (>= 0).
  T wave_modulus(const Mat3T& F, T) const {
    T s2_lo;
    detail::squared_stretch_bounds(F, &s2_lo);
    const T s_min = kMinSigma;
    const T e_lo = T(0.5) * std::log(std::max(s2_lo, s_min * s_min));
    const T tr_lo = std::log(std::max(std::abs(F.determinant()), s_min * s_min * s_min));
    return std::max(lambda + T(2) * mu - T(2) * mu * e_lo - lambda * tr_lo, T(0));
  }
};

}  // namespace shellmpm

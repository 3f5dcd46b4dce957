// Bulk MPM constitutive models behind one small interface (house style 5): energy
// density, first Piola-Kirchhoff stress, Kirchhoff stress and plasticity return mapping.
// The solver only calls kirchhoff() (or its batch form) for grid forces and project()
// after the deformation-gradient update, so elastic solids, sand and snow share one code
// path. Templated on the scalar so tests can run in double.
//
// Conventions. F is the (elastic) deformation gradient, 3x3, dimensionless. Energies are
// per unit rest volume [Pa = J/m^3]; P = dpsi/dF [Pa]; the Kirchhoff stress is
// tau = P F^T [Pa] (what the MPM grid force needs: f_i = -sum_p V_p^0 tau_p grad w_ip).
// Tension is positive. SVDs are the signed ones of sim/math/svd3.h: F = U diag(sigma) V^T
// with U, V rotations and sigma_2 < 0 for an inverted F. "plastic" is one per-particle
// scalar whose meaning depends on the model (snow: J_P; others: unused, 0).
//
// Models
// - Fixed corotated (Stomakhin, Howes, Schroeder, Teran 2012, "Energetically consistent
//   invertible elasticity", SCA; its fixed-corotated energy and first Piola stress):
//     psi = mu sum_i (sigma_i - 1)^2 + lambda/2 (J - 1)^2
//     P   = 2 mu (F - R) + lambda (J - 1) J F^-T,   R = U V^T, J F^-T = cof(F)
//     tau = 2 mu (F - R) F^T + lambda (J - 1) J I = U diag(2 mu (sigma_i - 1) sigma_i
//           + lambda (J - 1) J) U^T   (no inverse of F anywhere)
// - Compressible neo-Hookean (as in Bonet & Wood, "Nonlinear Continuum Mechanics for
//   Finite Element Analysis", ch. 6, written for F):
//     psi = mu/2 (tr(F^T F) - 3) - mu log J + lambda/2 (log J)^2
//     P   = mu (F - F^-T) + lambda log J F^-T
//     tau = mu (F F^T - I) + lambda log J I          (no SVD, no inverse)
//   log J is undefined for J <= 0 (inverted elements). We clamp J to kNeoHookeanMinJ
//   inside the logarithms (energy and stresses alike): the pressure lambda log J_c then
//   stays large and finite and pushes the element back out. Below kNeoHookeanMinJ the
//   energy and P are a regularization and no longer each other's derivative.
// - Sand: Drucker-Prager plasticity on the Hencky strain (Klar, Gast, Pradhana, Fu,
//   Schroeder, Jiang, Teran 2016, "Drucker-Prager elastoplasticity for sand animation",
//   SIGGRAPH: St. Venant-Kirchhoff energy in the Hencky strain; return mapping of its
//   sec. 7, cases I-III):
//     eps = log(Sigma), psi = mu tr(eps^2) + lambda/2 tr(eps)^2
//     tau = U diag(2 mu eps_i + lambda tr(eps)) U^T,   P = tau F^-T = U diag(tau_i /
//           sigma_i) V^T
//   Yield in strain space, with the cone tip moved to eps = c (1,1,1) by the cohesion c
//   (a Hencky strain): let e = eps - c, e_hat = e - tr(e)/3 (1,1,1) (deviatoric),
//   k = (3 lambda + 2 mu) / (2 mu), alpha = sqrt(2/3) 2 sin(phi) / (3 - sin(phi)):
//     case II  (tr(e) > 0, expansion):   eps <- c (1,1,1)            (cone tip)
//     otherwise dgamma = |e_hat| + k tr(e) alpha
//     case I   (dgamma <= 0, inside):    F untouched (bit for bit)
//     case III (dgamma > 0):             eps <- eps - dgamma e_hat / |e_hat|
//   then F = U diag(exp(eps)) V^T. The plastic scalar is not used (stays 0): the volume
//   correction of Tampubolon et al. 2017 is not applied. For |sigma_i| below
//   kHenckyMinSigma (10^4-fold compression, or an inverted F where |sigma| is used) the
//   strain is clamped at log(kHenckyMinSigma); energy and stress stay finite there. A
//   projected inverted F comes out non-inverted (exp(eps) > 0), as in common MPM codes.
// - Snow (Stomakhin, Schroeder, Chai, Teran, Selle 2013, "A material point method for
//   snow simulation", SIGGRAPH: energy eq. (1) and hardening eq. (2) of its constitutive
//   model, and the clamp of the singular values of F_E with F_P absorbing the rest in its
//   deformation-gradient update):
//   F holds the elastic part F_E; plastic = J_P, the plastic volume ratio (1 at rest).
//     psi = mu(J_P) sum (sigma_i - 1)^2 + lambda(J_P)/2 (J_E - 1)^2   (fixed corotated)
//     mu(J_P) = mu0 exp(xi (1 - J_P)),  lambda(J_P) = lambda0 exp(xi (1 - J_P))
//   Return mapping: sigma_i <- clamp(sigma_i, 1 - theta_c, 1 + theta_s),
//   J_P <- clamp(J_P prod(sigma_old) / prod(sigma_new), jp_min, jp_max) (keeps J_P J_E,
//   i.e. det F, unless a bound on J_P is hit), F_E <- U diag(sigma_new) V^T. An inverted
//   F_E (prod(sigma_old) < 0) counts as extreme compression: J_P goes to jp_min.
#pragma once
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>

#include "sim/core/check.h"
#include "sim/core/types.h"
#include "sim/math/svd3.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// One bulk material: parameters plus the model equations (see the file comment).
/// All methods are const, allocation-free and thread-safe.
template <class T>
struct ConstitutiveModelT {
  using Mat3T = Eigen::Matrix<T, 3, 3>;
  using Vec3T = Eigen::Matrix<T, 3, 1>;

  /// J below this is clamped inside the neo-Hookean logarithms.
  static constexpr T kNeoHookeanMinJ = T(1e-6);
  /// |sigma_i| below this is clamped in the Hencky strain of sand.
  static constexpr T kHenckyMinSigma = T(1e-4);

  MaterialKind kind = MaterialKind::Elastic;
  ElasticModel elastic = ElasticModel::FixedCorotated;  ///< used when kind == Elastic
  T mu = T(0), lambda = T(0);                           ///< Lame parameters (3D) from E, nu [Pa]
  T alpha = T(0);                    ///< sand: Drucker-Prager alpha (dimensionless)
  T cohesion = T(0);                 ///< sand: cone tip offset, a Hencky strain (>= 0)
  T theta_c = T(0), theta_s = T(0);  ///< snow: critical compression, stretch
  T xi = T(0);                       ///< snow: hardening coefficient
  T jp_min = T(1), jp_max = T(1);    ///< snow: clamp of J_P

  /// Model from a scene material. mu = E / (2 (1 + nu)), lambda = E nu / ((1 + nu)(1 - 2
  /// nu)); sand alpha = sqrt(2/3) 2 sin(phi) / (3 - sin(phi)). Checks the ranges
  /// (io/ reports user errors with file and line before this is reached).
  static ConstitutiveModelT from_desc(const MaterialDesc& desc);

  /// True for sand and snow (project() may change F).
  bool has_plasticity() const { return kind != MaterialKind::Elastic; }
  /// Plastic scalar of a particle at rest: snow J_P = 1; others 0.
  T initial_plastic() const { return kind == MaterialKind::Snow ? T(1) : T(0); }
  /// Snow hardening factor exp(xi (1 - J_P)) that multiplies mu and lambda; 1 otherwise.
  T hardening(T plastic) const {
    return kind == MaterialKind::Snow ? std::exp(xi * (T(1) - plastic)) : T(1);
  }

  /// Energy density per unit rest volume [Pa].
  T energy(const Mat3T& F, T plastic) const;
  /// First Piola-Kirchhoff stress P = dpsi/dF [Pa].
  Mat3T first_piola(const Mat3T& F, T plastic) const;
  /// Kirchhoff stress tau = P F^T [Pa], symmetric. Computed without inverting F.
  Mat3T kirchhoff(const Mat3T& F, T plastic) const;
  /// Plasticity return mapping in place (no-op for elastic materials).
  void project(Mat3T& F, T& plastic) const;
  /// project(F, plastic) followed by kirchhoff(F, plastic), sharing one SVD.
  Mat3T project_and_kirchhoff(Mat3T& F, T& plastic) const;
  /// Dilatational wave speed at rest, sqrt((lambda + 2 mu) / density) [m/s], with the
  /// current (snow: hardened) moduli; density in kg/m^3. Equals wave_speed(I, ...).
  T wave_speed(T density, T plastic) const;
  /// Upper bound on rho0 c^2 [Pa], c the spatial (Eulerian) longitudinal wave speed along
  /// any principal direction of the deformed state F, rho0 the rest density. In principal
  /// direction i, rho0 c_i^2 = d tau_i / d ln sigma_i - tau_i = sigma_i^2 d^2 psi / d
  /// sigma_i^2 (tau_i the principal Kirchhoff stress). Per model (h: snow hardening):
  ///   neo-Hookean:     mu (sigma_max^2 + 1) + lambda (1 - log J_c)
  ///   fixed corotated: h (2 mu sigma_max^2 + lambda J^2)   (snow alike)
  ///   sand (Hencky):   lambda + 2 mu - 2 mu log sigma_min - lambda log |J|   (>= 0)
  /// with sigma_max^2 and sigma_min^2 replaced by the cheap bounds of
  /// detail::squared_stretch_bounds (no SVD) and the Hencky clamp kHenckyMinSigma applied
  /// to the sand logarithms. Exactly lambda + 2 mu (times h) at F = I (and any rotation).
  /// Derived for longitudinal waves along the principal axes; on sampled states (J in
  /// [0.2, 3]) it also bounded the acoustic tensor over all directions and polarizations
  /// (tests/mpm/test_wave_speed.cpp checks the principal-axis bound only).
  T wave_modulus(const Mat3T& F, T plastic) const;
  /// sqrt(wave_modulus(F, plastic) / density) [m/s]: an upper bound on the spatial
  /// longitudinal wave speed of deformed material; density is the rest density [kg/m^3].
  T wave_speed(const Mat3T& F, T density, T plastic) const {
    return std::sqrt(wave_modulus(F, plastic) / density);
  }

  /// Batch forms over n particles (arrays of n entries). Same results as the per-particle
  /// calls up to rounding, but the SVDs run svd3_batch_width<T>() particles at a time in
  /// SIMD lanes (several times faster per particle). plastic may be nullptr for models
  /// that do not use it (then initial_plastic() is used).
  void kirchhoff_batch(const Mat3T* F, const T* plastic, Mat3T* tau, std::size_t n) const;
  void project_batch(Mat3T* F, T* plastic, std::size_t n) const;
  void project_and_kirchhoff_batch(Mat3T* F, T* plastic, Mat3T* tau, std::size_t n) const;

  // ---- building blocks on principal values (F = U diag(sigma) V^T) ----
  /// Principal Kirchhoff stresses tau_i (tau = U diag(tau_i) U^T) of the SVD-based models.
  Vec3T principal_kirchhoff(const Vec3T& sigma, T plastic) const;
  /// Return mapping on the singular values; returns false (and changes nothing) when the
  /// state is inside the yield surface.
  bool project_sigma(Vec3T& sigma, T& plastic) const;

 private:
  bool uses_svd() const {
    return !(kind == MaterialKind::Elastic && elastic == ElasticModel::NeoHookean);
  }
  template <bool kProject, bool kStress>
  void batch_impl(Mat3T* F_inout, const Mat3T* F_in, T* plastic_inout, const T* plastic_in,
                  Mat3T* tau, std::size_t n) const;
};

/// The model in the simulation precision.
using ConstitutiveModel = ConstitutiveModelT<Real>;

// ------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------
namespace detail {

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
  const T c00 = F.col(0).squaredNorm(), c11 = F.col(1).squaredNorm(),
          c22 = F.col(2).squaredNorm();
  const T c01 = F.col(0).dot(F.col(1)), c02 = F.col(0).dot(F.col(2)),
          c12 = F.col(1).dot(F.col(2));
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

}  // namespace detail

template <class T>
inline ConstitutiveModelT<T> ConstitutiveModelT<T>::from_desc(const MaterialDesc& d) {
  SHELLMPM_CHECK(d.youngs_modulus > 0.0, "material '" << d.name << "': E = " << d.youngs_modulus);
  SHELLMPM_CHECK(d.poisson_ratio > -1.0 && d.poisson_ratio < 0.5,
                 "material '" << d.name << "': nu = " << d.poisson_ratio);
  ConstitutiveModelT m;
  m.kind = d.kind;
  m.elastic = d.model;
  const double E = d.youngs_modulus, nu = d.poisson_ratio;
  m.mu = T(E / (2.0 * (1.0 + nu)));
  m.lambda = T(E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)));
  if (d.kind == MaterialKind::Sand) {
    SHELLMPM_CHECK(d.friction_angle_deg >= 0.0 && d.friction_angle_deg < 90.0,
                   "material '" << d.name << "': friction angle = " << d.friction_angle_deg);
    SHELLMPM_CHECK(d.cohesion >= 0.0, "material '" << d.name << "': cohesion = " << d.cohesion);
    const double s = std::sin(d.friction_angle_deg * 3.14159265358979323846 / 180.0);
    m.alpha = T(std::sqrt(2.0 / 3.0) * 2.0 * s / (3.0 - s));
    m.cohesion = T(d.cohesion);
  }
  if (d.kind == MaterialKind::Snow) {
    SHELLMPM_CHECK(d.critical_compression >= 0.0 && d.critical_compression < 1.0,
                   "material '" << d.name << "': theta_c = " << d.critical_compression);
    SHELLMPM_CHECK(d.critical_stretch >= 0.0,
                   "material '" << d.name << "': theta_s = " << d.critical_stretch);
    SHELLMPM_CHECK(d.hardening >= 0.0, "material '" << d.name << "': xi = " << d.hardening);
    SHELLMPM_CHECK(d.max_hardening_jp_min > 0.0 && d.max_hardening_jp_min <= d.max_hardening_jp_max,
                   "material '" << d.name << "': jp range [" << d.max_hardening_jp_min << ", "
                                << d.max_hardening_jp_max << "]");
    m.theta_c = T(d.critical_compression);
    m.theta_s = T(d.critical_stretch);
    m.xi = T(d.hardening);
    m.jp_min = T(d.max_hardening_jp_min);
    m.jp_max = T(d.max_hardening_jp_max);
  }
  return m;
}

template <class T>
inline typename ConstitutiveModelT<T>::Vec3T ConstitutiveModelT<T>::principal_kirchhoff(
    const Vec3T& sigma, T plastic) const {
  Vec3T tau;
  if (kind == MaterialKind::Sand) {
    const Vec3T e = detail::hencky_strain(sigma, kHenckyMinSigma);
    const T le = lambda * e.sum();
    for (int i = 0; i < 3; ++i) tau(i) = T(2) * mu * e(i) + le;
  } else {  // fixed corotated; snow with hardened moduli
    const T h = hardening(plastic);
    const T m2 = T(2) * mu * h;
    const T J = sigma(0) * sigma(1) * sigma(2);
    const T lj = lambda * h * (J - T(1)) * J;
    for (int i = 0; i < 3; ++i) tau(i) = m2 * (sigma(i) - T(1)) * sigma(i) + lj;
  }
  return tau;
}

template <class T>
inline bool ConstitutiveModelT<T>::project_sigma(Vec3T& sigma, T& plastic) const {
  if (kind == MaterialKind::Sand) {
    // Klar et al. 2016, sec. 7: return mapping onto the Drucker-Prager cone in Hencky
    // strain, tip shifted to eps = cohesion (1,1,1).
    const Vec3T eps = detail::hencky_strain(sigma, kHenckyMinSigma);
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
  if (kind == MaterialKind::Snow) {
    // Stomakhin et al. 2013: clamp the elastic singular values, move the volume change
    // into J_P.
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
  return false;
}

template <class T>
inline T ConstitutiveModelT<T>::energy(const Mat3T& F, T plastic) const {
  if (kind == MaterialKind::Elastic && elastic == ElasticModel::NeoHookean) {
    const T lj = std::log(std::max(F.determinant(), kNeoHookeanMinJ));
    return mu / T(2) * (F.squaredNorm() - T(3)) - mu * lj + lambda / T(2) * lj * lj;
  }
  Mat3T U, V;
  Vec3T sigma;
  svd3(F, U, sigma, V);
  if (kind == MaterialKind::Sand) {
    const Vec3T e = detail::hencky_strain(sigma, kHenckyMinSigma);
    const T tr = e.sum();
    return mu * e.squaredNorm() + lambda / T(2) * tr * tr;
  }
  const T h = hardening(plastic);
  const T J = sigma(0) * sigma(1) * sigma(2);
  return mu * h * (sigma.array() - T(1)).square().sum() +
         lambda * h / T(2) * (J - T(1)) * (J - T(1));
}

template <class T>
inline typename ConstitutiveModelT<T>::Mat3T ConstitutiveModelT<T>::first_piola(const Mat3T& F,
                                                                                T plastic) const {
  if (kind == MaterialKind::Elastic && elastic == ElasticModel::NeoHookean) {
    // P = mu F + (lambda log J_c - mu) cof(F) / J_c; exact for J > kNeoHookeanMinJ.
    const T Jc = std::max(F.determinant(), kNeoHookeanMinJ);
    return mu * F + ((lambda * std::log(Jc) - mu) / Jc) * detail::cofactor3(F);
  }
  Mat3T U, V;
  Vec3T sigma;
  svd3(F, U, sigma, V);
  if (kind == MaterialKind::Sand) {
    // P = U diag(tau_i / sigma_i) V^T, sigma_i kept away from 0 like the strain.
    const Vec3T tau = principal_kirchhoff(sigma, plastic);
    Vec3T d;
    for (int i = 0; i < 3; ++i) {
      const T s = std::max(std::abs(sigma(i)), kHenckyMinSigma);
      d(i) = tau(i) / (sigma(i) < T(0) ? -s : s);
    }
    return U * d.asDiagonal() * V.transpose();
  }
  // Fixed corotated: P = 2 mu (F - R) + lambda (J - 1) cof(F), R = U V^T.
  const T h = hardening(plastic);
  const T J = F.determinant();
  return T(2) * mu * h * (F - U * V.transpose()) + lambda * h * (J - T(1)) * detail::cofactor3(F);
}

template <class T>
inline typename ConstitutiveModelT<T>::Mat3T ConstitutiveModelT<T>::kirchhoff(const Mat3T& F,
                                                                              T plastic) const {
  if (!uses_svd()) {
    // Neo-Hookean: tau = mu (F F^T - I) + lambda log J_c I.
    const T lj = std::log(std::max(F.determinant(), kNeoHookeanMinJ));
    Mat3T tau = mu * (F * F.transpose());
    tau.diagonal().array() += lambda * lj - mu;
    return tau;
  }
  Mat3T U, V;
  Vec3T sigma;
  svd3(F, U, sigma, V);
  return detail::rotate_diagonal(U, principal_kirchhoff(sigma, plastic));
}

template <class T>
inline void ConstitutiveModelT<T>::project(Mat3T& F, T& plastic) const {
  if (!has_plasticity()) return;
  Mat3T U, V;
  Vec3T sigma;
  svd3(F, U, sigma, V);
  if (project_sigma(sigma, plastic)) F = U * sigma.asDiagonal() * V.transpose();
}

template <class T>
inline typename ConstitutiveModelT<T>::Mat3T ConstitutiveModelT<T>::project_and_kirchhoff(
    Mat3T& F, T& plastic) const {
  if (!uses_svd()) return kirchhoff(F, plastic);
  Mat3T U, V;
  Vec3T sigma;
  svd3(F, U, sigma, V);
  if (project_sigma(sigma, plastic)) F = U * sigma.asDiagonal() * V.transpose();
  return detail::rotate_diagonal(U, principal_kirchhoff(sigma, plastic));
}

template <class T>
inline T ConstitutiveModelT<T>::wave_speed(T density, T plastic) const {
  return std::sqrt((lambda + T(2) * mu) * hardening(plastic) / density);
}

template <class T>
inline T ConstitutiveModelT<T>::wave_modulus(const Mat3T& F, T plastic) const {
  if (kind == MaterialKind::Sand) {
    // tau_i = 2 mu e_i + lambda tr(e) gives d tau_i / d e_i - tau_i <= lambda + 2 mu - tau_i
    // (equal where sigma_i is not clamped); e_i >= log sigma_min, tr(e) >= log |J|.
    T s2_lo;
    detail::squared_stretch_bounds(F, &s2_lo);
    const T s_min = kHenckyMinSigma;
    const T e_lo = T(0.5) * std::log(std::max(s2_lo, s_min * s_min));
    const T tr_lo = std::log(std::max(std::abs(F.determinant()), s_min * s_min * s_min));
    return std::max(lambda + T(2) * mu - T(2) * mu * e_lo - lambda * tr_lo, T(0));
  }
  const T s2_max = detail::squared_stretch_bounds(F);
  const T J = F.determinant();
  if (kind == MaterialKind::Elastic && elastic == ElasticModel::NeoHookean) {
    // tau_i = mu (sigma_i^2 - 1) + lambda log J_c.
    const T lj = std::log(std::max(J, kNeoHookeanMinJ));
    return mu * (s2_max + T(1)) + lambda * (T(1) - lj);
  }
  // Fixed corotated, snow: tau_i = 2 mu h (sigma_i - 1) sigma_i + lambda h (J - 1) J.
  return hardening(plastic) * (T(2) * mu * s2_max + lambda * J * J);
}

template <class T>
template <bool kProject, bool kStress>
inline void ConstitutiveModelT<T>::batch_impl(Mat3T* F_inout, const Mat3T* F_in, T* plastic_inout,
                                              const T* plastic_in, Mat3T* tau,
                                              std::size_t n) const {
  constexpr int W = svd3_batch_width<T>();
  Mat3T U[W], V[W];
  Vec3T sigma[W];
  const T p0 = initial_plastic();
  for (std::size_t base = 0; base < n; base += W) {
    const std::size_t cnt = std::min<std::size_t>(W, n - base);
    const Mat3T* Fb = kProject ? F_inout + base : F_in + base;
    svd3_batch(Fb, cnt, U, sigma, V);
    for (std::size_t k = 0; k < cnt; ++k) {
      const std::size_t i = base + k;
      T p = kProject ? (plastic_inout ? plastic_inout[i] : p0) : (plastic_in ? plastic_in[i] : p0);
      if (kProject && project_sigma(sigma[k], p)) {
        F_inout[i] = U[k] * sigma[k].asDiagonal() * V[k].transpose();
        if (plastic_inout) plastic_inout[i] = p;
      }
      if (kStress) tau[i] = detail::rotate_diagonal(U[k], principal_kirchhoff(sigma[k], p));
    }
  }
}

template <class T>
inline void ConstitutiveModelT<T>::kirchhoff_batch(const Mat3T* F, const T* plastic, Mat3T* tau,
                                                   std::size_t n) const {
  if (!uses_svd()) {
    for (std::size_t i = 0; i < n; ++i)
      tau[i] = kirchhoff(F[i], plastic ? plastic[i] : initial_plastic());
    return;
  }
  batch_impl<false, true>(nullptr, F, nullptr, plastic, tau, n);
}

template <class T>
inline void ConstitutiveModelT<T>::project_batch(Mat3T* F, T* plastic, std::size_t n) const {
  if (!has_plasticity()) return;
  SHELLMPM_CHECK(plastic != nullptr || kind != MaterialKind::Snow, "snow needs J_P");
  batch_impl<true, false>(F, nullptr, plastic, nullptr, nullptr, n);
}

template <class T>
inline void ConstitutiveModelT<T>::project_and_kirchhoff_batch(Mat3T* F, T* plastic, Mat3T* tau,
                                                               std::size_t n) const {
  if (!uses_svd()) {
    kirchhoff_batch(F, plastic, tau, n);
    return;
  }
  SHELLMPM_CHECK(plastic != nullptr || kind != MaterialKind::Snow, "snow needs J_P");
  batch_impl<true, true>(F, nullptr, plastic, nullptr, tau, n);
}

}  // namespace shellmpm

// Bulk MPM materials behind one small interface (house style 5): energy density, first
// Piola-Kirchhoff stress, Kirchhoff stress, plasticity return mapping and wave-speed
// bound. Each model is one file in sim/mpm/materials/ (fixed_corotated, neo_hookean,
// drucker_prager for sand, snow; conventions in material_math.h); ConstitutiveModelT
// holds one of them in a std::variant, built from the scene material by from_desc (the
// one place a model is registered). The batch calls the solver uses (kirchhoff_batch,
// project_batch) dispatch once per batch, so the per-particle loops inside run one
// model's code without branching on the kind. The per-particle calls dispatch per call.
// Templated on the scalar so tests can run in double.
#pragma once
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <type_traits>
#include <variant>

#include "sim/core/check.h"
#include "sim/core/types.h"
#include "sim/math/svd3.h"
#include "sim/mpm/materials/drucker_prager.h"
#include "sim/mpm/materials/fixed_corotated.h"
#include "sim/mpm/materials/neo_hookean.h"
#include "sim/mpm/materials/snow.h"
#include "sim/mpm/stress_batch.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// One bulk material: its model (parameters and equations) plus a description for
/// reports. All methods are const, allocation-free and thread-safe.
template <class T>
struct ConstitutiveModelT {
  using Mat3T = Eigen::Matrix<T, 3, 3>;
  using Vec3T = Eigen::Matrix<T, 3, 1>;
  using Model = std::variant<FixedCorotatedT<T>, NeoHookeanT<T>, DruckerPragerT<T>, SnowT<T>>;

  /// J below this is clamped inside the neo-Hookean logarithms.
  static constexpr T kNeoHookeanMinJ = NeoHookeanT<T>::kMinJ;
  /// |sigma_i| below this is clamped in the Hencky strain of sand.
  static constexpr T kHenckyMinSigma = DruckerPragerT<T>::kMinSigma;

  Model model;  ///< the equations and their parameters (default: fixed corotated, 0 moduli)
  // The description (read-only use: reports, tests).
  MaterialKind kind = MaterialKind::Elastic;
  ElasticModel elastic = ElasticModel::FixedCorotated;  ///< used when kind == Elastic
  T mu = T(0), lambda = T(0);                           ///< Lame parameters (3D) from E, nu [Pa]

  /// Model from a scene material. mu = E / (2 (1 + nu)), lambda = E nu / ((1 + nu)(1 - 2
  /// nu)); sand alpha = sqrt(2/3) 2 sin(phi) / (3 - sin(phi)). Checks the ranges
  /// (io/ reports user errors with file and line before this is reached).
  static ConstitutiveModelT from_desc(const MaterialDesc& desc);

  /// True for sand and snow (project() may change F).
  bool has_plasticity() const {
    return std::visit([](const auto& m) { return m.kPlastic; }, model);
  }
  /// Plastic scalar of a particle at rest: snow J_P = 1; others 0.
  T initial_plastic() const {
    return std::visit([](const auto& m) { return m.initial_plastic(); }, model);
  }
  /// Snow hardening factor exp(xi (1 - J_P)) that multiplies mu and lambda; 1 otherwise.
  T hardening(T plastic) const {
    return std::visit([&](const auto& m) { return m.hardening(plastic); }, model);
  }

  /// The largest hardening factor the material can reach (snow: at J_P = jp_min; 1
  /// otherwise).
  T max_hardening() const {
    return std::visit(
        [](const auto& m) {
          using M = std::decay_t<decltype(m)>;
          if constexpr (std::is_same_v<M, SnowT<T>>)
            return m.hardening(m.jp_min);
          else
            return T(1);
        },
        model);
  }

  /// Energy density per unit rest volume [Pa].
  T energy(const Mat3T& F, T plastic) const {
    return std::visit([&](const auto& m) { return m.energy(F, plastic); }, model);
  }
  /// First Piola-Kirchhoff stress P = dpsi/dF [Pa].
  Mat3T first_piola(const Mat3T& F, T plastic) const {
    return std::visit([&](const auto& m) { return Mat3T(m.first_piola(F, plastic)); }, model);
  }
  /// Kirchhoff stress tau = P F^T [Pa], symmetric. Computed without inverting F.
  Mat3T kirchhoff(const Mat3T& F, T plastic) const {
    return std::visit([&](const auto& m) { return kirchhoff_of(m, F, plastic); }, model);
  }
  /// Plasticity return mapping in place (no-op for elastic materials).
  void project(Mat3T& F, T& plastic) const {
    std::visit([&](const auto& m) { project_of(m, F, plastic); }, model);
  }
  /// project(F, plastic) followed by kirchhoff(F, plastic), sharing one SVD.
  Mat3T project_and_kirchhoff(Mat3T& F, T& plastic) const {
    return std::visit(
        [&](const auto& m) -> Mat3T {
          using M = std::decay_t<decltype(m)>;
          if constexpr (!M::kUsesSvd) {
            return kirchhoff_of(m, F, plastic);
          } else {
            Mat3T U, V;
            Vec3T sigma;
            svd3(F, U, sigma, V);
            if (m.project_sigma(sigma, plastic)) F = U * sigma.asDiagonal() * V.transpose();
            return detail::rotate_diagonal(U, m.principal_kirchhoff(sigma, plastic));
          }
        },
        model);
  }
  /// Dilatational wave speed at rest, sqrt((lambda + 2 mu) / density) [m/s], with the
  /// current (snow: hardened) moduli; density in kg/m^3. Equals wave_speed(I, ...).
  T wave_speed(T density, T plastic) const {
    return std::sqrt((lambda + T(2) * mu) * hardening(plastic) / density);
  }
  /// Upper bound on rho0 c^2 [Pa], c the spatial (Eulerian) longitudinal wave speed along
  /// any principal direction of the deformed state F, rho0 the rest density. In principal
  /// direction i, rho0 c_i^2 = d tau_i / d ln sigma_i - tau_i = sigma_i^2 d^2 psi / d
  /// sigma_i^2 (tau_i the principal Kirchhoff stress); each model's file gives its bound,
  /// with sigma_max^2 and sigma_min^2 replaced by the cheap bounds of
  /// detail::squared_stretch_bounds (no SVD). Exactly lambda + 2 mu (times h) at F = I
  /// (and any rotation). Derived for longitudinal waves along the principal axes; on
  /// sampled states (J in [0.2, 3]) it also bounded the acoustic tensor over all
  /// directions and polarizations (tests/sim/mpm/test_wave_speed.cpp checks the
  /// principal-axis bound only).
  T wave_modulus(const Mat3T& F, T plastic) const {
    return std::visit([&](const auto& m) { return m.wave_modulus(F, plastic); }, model);
  }
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

 private:
  template <class M>
  static Mat3T kirchhoff_of(const M& m, const Mat3T& F, T plastic) {
    if constexpr (!M::kUsesSvd) {
      return m.kirchhoff(F, plastic);
    } else {
      Mat3T U, V;
      Vec3T sigma;
      svd3(F, U, sigma, V);
      return detail::rotate_diagonal(U, m.principal_kirchhoff(sigma, plastic));
    }
  }
  template <class M>
  static void project_of(const M& m, Mat3T& F, T& plastic) {
    if constexpr (M::kPlastic) {
      Mat3T U, V;
      Vec3T sigma;
      svd3(F, U, sigma, V);
      if (m.project_sigma(sigma, plastic)) F = U * sigma.asDiagonal() * V.transpose();
    }
  }

 public:
  /// The batch loop for model m (what the batch calls run; stress_batch.h compiles it per
  /// instruction set).
  template <bool kProject, bool kStress, class M>
  static void batch_impl(const M& m, Mat3T* F_inout, const Mat3T* F_in, T* plastic_inout,
                         const T* plastic_in, Mat3T* tau, std::size_t n);
};

/// The model in the simulation precision.
using ConstitutiveModel = ConstitutiveModelT<Real>;

// ------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------

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
    DruckerPragerT<T> dp;
    dp.mu = m.mu;
    dp.lambda = m.lambda;
    dp.alpha = T(std::sqrt(2.0 / 3.0) * 2.0 * s / (3.0 - s));
    dp.cohesion = T(d.cohesion);
    m.model = dp;
  } else if (d.kind == MaterialKind::Snow) {
    SHELLMPM_CHECK(d.critical_compression >= 0.0 && d.critical_compression < 1.0,
                   "material '" << d.name << "': theta_c = " << d.critical_compression);
    SHELLMPM_CHECK(d.critical_stretch >= 0.0,
                   "material '" << d.name << "': theta_s = " << d.critical_stretch);
    SHELLMPM_CHECK(d.hardening >= 0.0, "material '" << d.name << "': xi = " << d.hardening);
    SHELLMPM_CHECK(d.max_hardening_jp_min > 0.0 && d.max_hardening_jp_min <= d.max_hardening_jp_max,
                   "material '" << d.name << "': jp range [" << d.max_hardening_jp_min << ", "
                                << d.max_hardening_jp_max << "]");
    SnowT<T> sn;
    sn.mu = m.mu;
    sn.lambda = m.lambda;
    sn.theta_c = T(d.critical_compression);
    sn.theta_s = T(d.critical_stretch);
    sn.xi = T(d.hardening);
    sn.jp_min = T(d.max_hardening_jp_min);
    sn.jp_max = T(d.max_hardening_jp_max);
    m.model = sn;
  } else if (d.model == ElasticModel::NeoHookean) {
    m.model = NeoHookeanT<T>{m.mu, m.lambda};
  } else {
    m.model = FixedCorotatedT<T>{m.mu, m.lambda};
  }
  return m;
}

template <class T>
template <bool kProject, bool kStress, class M>
inline void ConstitutiveModelT<T>::batch_impl(const M& m, Mat3T* F_inout, const Mat3T* F_in,
                                              T* plastic_inout, const T* plastic_in, Mat3T* tau,
                                              std::size_t n) {
  constexpr int W = svd3_batch_width<T>();
  Mat3T U[W], V[W];
  Vec3T sigma[W];
  const T p0 = m.initial_plastic();
  for (std::size_t base = 0; base < n; base += W) {
    const std::size_t cnt = std::min<std::size_t>(W, n - base);
    const Mat3T* Fb = kProject ? F_inout + base : F_in + base;
    svd3_batch(Fb, cnt, U, sigma, V);
    for (std::size_t k = 0; k < cnt; ++k) {
      const std::size_t i = base + k;
      T p = kProject ? (plastic_inout ? plastic_inout[i] : p0) : (plastic_in ? plastic_in[i] : p0);
      if (kProject && m.project_sigma(sigma[k], p)) {
        F_inout[i] = U[k] * sigma[k].asDiagonal() * V[k].transpose();
        if (plastic_inout) plastic_inout[i] = p;
      }
      if (kStress) tau[i] = detail::rotate_diagonal(U[k], m.principal_kirchhoff(sigma[k], p));
    }
  }
}

template <class T>
inline void ConstitutiveModelT<T>::kirchhoff_batch(const Mat3T* F, const T* plastic, Mat3T* tau,
                                                   std::size_t n) const {
  std::visit(
      [&](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        if constexpr (!M::kUsesSvd) {
          for (std::size_t i = 0; i < n; ++i)
            tau[i] = m.kirchhoff(F[i], plastic ? plastic[i] : m.initial_plastic());
        } else {
          if constexpr (std::is_same_v<T, Real>)
            if (stress_batch::kirchhoff(*this, F, plastic, tau, n)) return;
          batch_impl<false, true>(m, nullptr, F, nullptr, plastic, tau, n);
        }
      },
      model);
}

template <class T>
inline void ConstitutiveModelT<T>::project_batch(Mat3T* F, T* plastic, std::size_t n) const {
  std::visit(
      [&](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        if constexpr (M::kPlastic) {
          constexpr bool kSnow = std::is_same_v<M, SnowT<T>>;
          SHELLMPM_CHECK(plastic != nullptr || !kSnow, "snow needs J_P");
          if constexpr (std::is_same_v<T, Real>)
            if (stress_batch::project(*this, F, plastic, n)) return;
          batch_impl<true, false>(m, F, nullptr, plastic, nullptr, nullptr, n);
        }
      },
      model);
}

template <class T>
inline void ConstitutiveModelT<T>::project_and_kirchhoff_batch(Mat3T* F, T* plastic, Mat3T* tau,
                                                               std::size_t n) const {
  std::visit(
      [&](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        if constexpr (!M::kUsesSvd) {
          kirchhoff_batch(F, plastic, tau, n);
        } else {
          constexpr bool kSnow = std::is_same_v<M, SnowT<T>>;
          SHELLMPM_CHECK(plastic != nullptr || !kSnow, "snow needs J_P");
          if constexpr (std::is_same_v<T, Real>)
            if (stress_batch::project_and_kirchhoff(*this, F, plastic, tau, n)) return;
          batch_impl<true, true>(m, F, nullptr, plastic, nullptr, tau, n);
        }
      },
      model);
}

}  // namespace shellmpm

#include "sim/shell/denting.h"

#include <algorithm>
#include <cmath>

namespace shellmpm {

template <class T>
Eigen::Matrix<T, 2, 1> denting_principal_stress(T mu, T lambda, const Eigen::Matrix<T, 2, 1>& l) {
  const T tr = l(0) + l(1);
  return Eigen::Matrix<T, 2, 1>(T(2) * mu * l(0) + lambda * tr, T(2) * mu * l(1) + lambda * tr);
}

template <class T>
T denting_yield_function(T tau1, T tau2, T yield_stress) {
  const T two_sy = T(2) * yield_stress;
  const T fp = std::abs(tau1 + tau2) / two_sy;
  const T fd = std::sqrt(T(3)) * std::abs(tau1 - tau2) / two_sy;
  return std::max(fp, fd) - T(1);
}

template <class T>
T denting_energy_density(T mu, T lambda, const Eigen::Matrix<T, 2, 1>& l) {
  const T tr = l(0) + l(1);
  return mu * (l(0) * l(0) + l(1) * l(1)) + T(0.5) * lambda * tr * tr;
}

template <class T>
bool denting_return_map(T mu, T lambda, T yield_stress, Eigen::Matrix<T, 2, 1>& l) {
  // In the eigenbasis of the moduli of eq. (36): p = tau_1 + tau_2 = 2 (mu + lambda) S,
  // d = tau_1 - tau_2 = 2 mu D, with S = l_1 + l_2 and D = l_1 - l_2.
  const Eigen::Matrix<T, 2, 1> tau = denting_principal_stress(mu, lambda, l);
  const T p = tau(0) + tau(1), d = tau(0) - tau(1);
  const T p_max = T(2) * yield_stress;
  const T d_max = T(2) * yield_stress / std::sqrt(T(3));
  const bool clamp_p = std::abs(p) > p_max, clamp_d = std::abs(d) > d_max;
  if (!clamp_p && !clamp_d) return false;
  T S = l(0) + l(1), D = l(0) - l(1);
  // Perpendicular return: clamp each coordinate; eq. (36) inverted in that basis.
  if (clamp_p) S = std::copysign(p_max, p) / (T(2) * (mu + lambda));
  if (clamp_d) D = std::copysign(d_max, d) / (T(2) * mu);
  l(0) = T(0.5) * (S + D);
  l(1) = T(0.5) * (S - D);
  return true;
}

template <class T>
T denting_project_layer(T mu, T lambda, T yield_stress, const Eigen::Matrix<T, 2, 2>& Ce,
                        Eigen::Matrix<T, 2, 2>& Fp_inv, bool* yielded) {
  if (yielded) *yielded = false;
  // Spectral decomposition of the symmetric 2x2 Ce (done in double: this runs once per
  // layer and step, and float cancellation here would leak into the plastic state).
  const double a = Ce(0, 0), b = 0.5 * (double(Ce(0, 1)) + double(Ce(1, 0))), c = Ce(1, 1);
  const double half_tr = 0.5 * (a + c);
  const double h = std::hypot(0.5 * (a - c), b);
  const double c1 = half_tr + h;
  const double c2 = (a * c - b * b) / c1;  // det / c1: no cancellation
  Eigen::Matrix<double, 2, 1> ld(0.5 * std::log(c1), 0.5 * std::log(c2));
  Eigen::Matrix<T, 2, 1> l = ld.template cast<T>();
  const Eigen::Matrix<T, 2, 1> l_trial = l;
  if (!denting_return_map(mu, lambda, yield_stress, l)) return T(0);
  if (yielded) *yielded = true;
  const double theta = 0.5 * std::atan2(2.0 * b, a - c);  // eigenvector of c1
  const double cs = std::cos(theta), sn = std::sin(theta);
  Eigen::Matrix2d V;
  V << cs, -sn, sn, cs;
  const Eigen::Vector2d scale(std::exp(double(l(0)) - ld(0)), std::exp(double(l(1)) - ld(1)));
  const Eigen::Matrix2d Fi =
      Fp_inv.template cast<double>() * V * scale.asDiagonal() * V.transpose();
  Fp_inv = Fi.cast<T>();
  // The plastic work: the returned stress times the plastic strain increment.
  const Eigen::Matrix<T, 2, 1> tau = denting_principal_stress(mu, lambda, l);
  return std::max(tau.dot(l_trial - l), T(0));
}

#define SHELLMPM_DENTING_INSTANTIATE(T)                                                       \
  template Eigen::Matrix<T, 2, 1> denting_principal_stress<T>(T, T,                           \
                                                              const Eigen::Matrix<T, 2, 1>&); \
  template T denting_yield_function<T>(T, T, T);                                              \
  template T denting_energy_density<T>(T, T, const Eigen::Matrix<T, 2, 1>&);                  \
  template bool denting_return_map<T>(T, T, T, Eigen::Matrix<T, 2, 1>&);                      \
  template T denting_project_layer<T>(T, T, T, const Eigen::Matrix<T, 2, 2>&,                 \
                                      Eigen::Matrix<T, 2, 2>&, bool*);
SHELLMPM_DENTING_INSTANTIATE(float)
SHELLMPM_DENTING_INSTANTIATE(double)
#undef SHELLMPM_DENTING_INSTANTIATE

}  // namespace shellmpm

// Mid-surface kinematics of a Kirchhoff-Love shell at one quadrature point (Guo et al.
// 2018, supplement sec. 1), gathered from the control points with the Loop basis
// weights. Internal to sim/shell (kirchhoff_love*.cpp).
#pragma once
#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace shellmpm::kl {

constexpr std::size_t kPointGrain = 256;  ///< quadrature points per parallel chunk

/// Mid-surface kinematics at one quadrature point (supplement sec. 1):
/// a_a, a_ab, a_3, atilde_a = (a_1,a x a_2 + a_1 x a_2,a) / |a_1 x a_2|, and
/// v_a = a_3,a = (I - a_3 a_3^T) atilde_a.
template <class T>
struct PointKinematics {
  using V3 = Eigen::Matrix<T, 3, 1>;
  V3 a1, a2, a11, a12, a22, a3, t1, t2, v1, v2;
  T inv_l;
};

template <class T>
inline void compute_kinematics(PointKinematics<T>& k) {
  using V3 = Eigen::Matrix<T, 3, 1>;
  const V3 n = k.a1.cross(k.a2);
  k.inv_l = T(1) / n.norm();
  k.a3 = n * k.inv_l;
  k.t1 = (k.a11.cross(k.a2) + k.a1.cross(k.a12)) * k.inv_l;
  k.t2 = (k.a12.cross(k.a2) + k.a1.cross(k.a22)) * k.inv_l;
  k.v1 = k.t1 - k.a3 * k.a3.dot(k.t1);
  k.v2 = k.t2 - k.a3 * k.a3.dot(k.t2);
}

/// a_alpha and a_alphabeta at quadrature point q (entries [begin[q], begin[q+1]) with 5
/// weights each): out = (a_1, a_2, a_11, a_12, a_22). The derivative weights of a point sum
/// to zero (partition of unity), so the sums run over differences to the point's first
/// control point: in float this keeps a_alpha and the small a_alphabeta accurate far
/// from the origin.
template <class T>
inline void gather_derivatives(const std::vector<std::size_t>& begin, const std::vector<int>& ctrl,
                               const std::vector<T>& coef, std::size_t q,
                               const Eigen::Matrix<T, 3, 1>* x, Eigen::Matrix<T, 3, 1> (&out)[5]) {
  for (auto& a : out) a.setZero();
  const Eigen::Matrix<T, 3, 1>& x0 = x[ctrl[begin[q]]];
  for (std::size_t e = begin[q] + 1; e < begin[q + 1]; ++e) {
    const Eigen::Matrix<T, 3, 1> dx = x[ctrl[e]] - x0;
    const T* c = &coef[5 * e];
    for (int i = 0; i < 5; ++i) out[i] += c[i] * dx;
  }
}

/// gather_derivatives, then the rest of the kinematics.
template <class T>
void gather_kinematics(const std::vector<std::size_t>& begin, const std::vector<int>& ctrl,
                       const std::vector<T>& coef, std::size_t q, const Eigen::Matrix<T, 3, 1>* x,
                       PointKinematics<T>& k) {
  Eigen::Matrix<T, 3, 1> a[5];
  gather_derivatives(begin, ctrl, coef, q, x, a);
  k.a1 = a[0];
  k.a2 = a[1];
  k.a11 = a[2];
  k.a12 = a[3];
  k.a22 = a[4];
  compute_kinematics(k);
}

}  // namespace shellmpm::kl

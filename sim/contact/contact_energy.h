// Contact elasticity of one contact particle (Guo et al. 2018, supplement sections 4-5,
// eqs. 9-23; Jiang, Gast, Teran 2017 for the QR formulation). The friction return
// mapping (section 6) is in friction_return_map.h.
//
// A contact particle sits at a fixed parametric site of a shell. Its elastic
// deformation has the columns D = [a_1, a_2, a3E]: the surface tangents (from the control
// points) and its own normal column a3E (advected with the grid). QR of D by
// Gram-Schmidt, q_3 = q_1 x q_2, gives R = Q^T D upper triangular; only its third column
// s = (r13, r23, r33) = Q^T a3E enters the energy:
//   psi = gamma/2 (s1^2 + s2^2) + f(s3),  f(x) = k_c/3 (1 - x)^3 for x <= 1, else 0.
// s3 < 1 is compression of the normal column (contact), (s1, s2) its shear.
#pragma once
#include <cmath>

#include "sim/core/types.h"

namespace shellmpm {

/// Contact material of a shell: shear stiffness gamma [Pa], normal stiffness k_c [Pa],
/// Coulomb friction coefficient c_F.
struct ContactParams {
  double gamma = 0;
  double kc = 0;
  double friction = 0;
};

template <class T>
struct ContactFrameT {
  using V3 = Eigen::Matrix<T, 3, 1>;
  V3 q[3];          ///< orthonormal frame: q1 along a_1, q3 the unit normal
  T r11, r12, r22;  ///< in-plane block of R
  V3 s;             ///< third column of R: Q^T a3E
};

/// The Gram-Schmidt QR of [a1, a2, a3E] by components: T is a scalar or a GCC vector of
/// lanes (each lane the same operations: ShellContact's frames of several sites at once);
/// root(x) takes the square root of x in place.
template <class T, class Root>
inline void contact_frame_parts(const T (&a1)[3], const T (&a2)[3], const T (&a3e)[3], Root root,
                                T (&q)[3][3], T& r11, T& r12, T& r22, T (&s)[3]) {
  const auto dot = [](const T(&u)[3], const T(&v)[3], T& out) {
    out = (u[0] * v[0] + u[1] * v[1]) + u[2] * v[2];
  };
  dot(a1, a1, r11);
  root(r11);
  for (int c = 0; c < 3; ++c) q[0][c] = a1[c] / r11;
  dot(q[0], a2, r12);
  T u[3];
  for (int c = 0; c < 3; ++c) u[c] = a2[c] - r12 * q[0][c];
  dot(u, u, r22);
  root(r22);
  for (int c = 0; c < 3; ++c) q[1][c] = u[c] / r22;
  q[2][0] = q[0][1] * q[1][2] - q[0][2] * q[1][1];
  q[2][1] = q[0][2] * q[1][0] - q[0][0] * q[1][2];
  q[2][2] = q[0][0] * q[1][1] - q[0][1] * q[1][0];
  for (int i = 0; i < 3; ++i) dot(q[i], a3e, s[i]);
}

/// Gram-Schmidt QR of [a1, a2, a3E] (a1, a2 must be independent).
template <class T>
ContactFrameT<T> contact_frame(const Eigen::Matrix<T, 3, 1>& a1, const Eigen::Matrix<T, 3, 1>& a2,
                               const Eigen::Matrix<T, 3, 1>& a3e) {
  const T b1[3] = {a1[0], a1[1], a1[2]}, b2[3] = {a2[0], a2[1], a2[2]},
          b3[3] = {a3e[0], a3e[1], a3e[2]};
  T q[3][3], s[3];
  ContactFrameT<T> f;
  contact_frame_parts(
      b1, b2, b3, [](T& x) { x = std::sqrt(x); }, q, f.r11, f.r12, f.r22, s);
  for (int i = 0; i < 3; ++i) f.q[i] = Eigen::Matrix<T, 3, 1>(q[i][0], q[i][1], q[i][2]);
  f.s = Eigen::Matrix<T, 3, 1>(s[0], s[1], s[2]);
  return f;
}

/// psi(s) [Pa = J/m^3]. (The supplement's f and gamma term.)
template <class T>
T contact_energy_density(const Eigen::Matrix<T, 3, 1>& s, const ContactParams& p) {
  const T g = static_cast<T>(p.gamma), kc = static_cast<T>(p.kc);
  T e = g / 2 * (s[0] * s[0] + s[1] * s[1]);
  if (s[2] < 1) {
    const T c = 1 - s[2];
    e += kc / 3 * c * c * c;
  }
  return e;
}

/// d psi / d s.
template <class T>
Eigen::Matrix<T, 3, 1> contact_dpsi_ds(const Eigen::Matrix<T, 3, 1>& s, const ContactParams& p) {
  const T g = static_cast<T>(p.gamma), kc = static_cast<T>(p.kc);
  const T c = s[2] < 1 ? 1 - s[2] : T(0);
  return Eigen::Matrix<T, 3, 1>(g * s[0], g * s[1], -kc * c * c);
}

/// contact_gradient's arithmetic from the frame (q, r11, r12, r22, s of
/// contact_frame_parts) on scalars or lanes: T is E or a GCC vector of E (each lane the
/// same operations, so the same bits as one site alone). Outputs psi and the columns
/// g[col][component] of G (see contact_gradient).
template <class E, class T>
inline void contact_gradient_parts(const T (&q)[3][3], const T& r11, const T& r12, const T& r22,
                                   const T (&s)[3], const ContactParams& p, T& psi, T (&g)[3][3]) {
  const E gamma = static_cast<E>(p.gamma), kc = static_cast<E>(p.kc);
  const auto compressed = s[2] < E(1);  // a lane mask for vectors
  const T zero{};
  // As contact_energy_density and contact_dpsi_ds, in their order of operations.
  const T c = compressed ? E(1) - s[2] : zero;
  const T shear = gamma / E(2) * (s[0] * s[0] + s[1] * s[1]);
  psi = compressed ? shear + kc / E(3) * c * c * c : shear;
  const T d[3] = {gamma * s[0], gamma * s[1], -kc * c * c};
  const T k = gamma * s[2] - d[2];
  const T l1 = s[0] * k, l2 = s[1] * k;
  const T m2 = l2 / r22;
  const T m1 = (l1 - r12 * m2) / r11;
  for (int i = 0; i < 3; ++i) {
    g[0][i] = m1 * q[2][i];
    g[1][i] = m2 * q[2][i];
    g[2][i] = (d[0] * q[0][i] + d[1] * q[1][i]) + d[2] * q[2][i];
  }
}

/// Gradient of psi with respect to the columns of D: G.col(0) = dpsi/da1,
/// G.col(1) = dpsi/da2, G.col(2) = dpsi/da3E. Equal to tau D^-T (tau the Kirchhoff
/// stress), written without D^-1: G.col(2) = Q dpsi/ds and G.col(beta) = m_beta q3 with
/// m = R2^-1 l, l_beta = s_beta (gamma s3 - f'(s3)) (the rows of L in B = A + L, where
/// A = P R^T and B is the symmetric eq. (21) stress in the q basis). No division by s3,
/// so it stays finite for any compression. Returns psi.
template <class T>
T contact_gradient(const Eigen::Matrix<T, 3, 1>& a1, const Eigen::Matrix<T, 3, 1>& a2,
                   const Eigen::Matrix<T, 3, 1>& a3e, const ContactParams& p,
                   Eigen::Matrix<T, 3, 3>* G) {
  const T b1[3] = {a1[0], a1[1], a1[2]}, b2[3] = {a2[0], a2[1], a2[2]},
          b3[3] = {a3e[0], a3e[1], a3e[2]};
  T q[3][3], s[3], r11, r12, r22, psi, g[3][3];
  contact_frame_parts(
      b1, b2, b3, [](T& x) { x = std::sqrt(x); }, q, r11, r12, r22, s);
  contact_gradient_parts<T>(q, r11, r12, r22, s, p, psi, g);
  if (G)
    for (int c = 0; c < 3; ++c) G->col(c) = Eigen::Matrix<T, 3, 1>(g[c][0], g[c][1], g[c][2]);
  return psi;
}

/// Kirchhoff stress tau = Q B Q^T, B the supplement's eq. (23) (with the (3,3) entry
/// f'(s3) s3, see METHOD.md).
template <class T>
Eigen::Matrix<T, 3, 3> contact_kirchhoff(const Eigen::Matrix<T, 3, 1>& a1,
                                         const Eigen::Matrix<T, 3, 1>& a2,
                                         const Eigen::Matrix<T, 3, 1>& a3e,
                                         const ContactParams& p) {
  const ContactFrameT<T> f = contact_frame(a1, a2, a3e);
  const Eigen::Matrix<T, 3, 1> d = contact_dpsi_ds(f.s, p);
  const T g = static_cast<T>(p.gamma);
  const T s1 = f.s[0], s2 = f.s[1], s3 = f.s[2];
  Eigen::Matrix<T, 3, 3> B;
  B << g * s1 * s1, g * s1 * s2, g * s1 * s3,  //
      g * s1 * s2, g * s2 * s2, g * s2 * s3,   //
      g * s1 * s3, g * s2 * s3, d[2] * s3;
  Eigen::Matrix<T, 3, 3> Q;
  for (int i = 0; i < 3; ++i) Q.col(i) = f.q[i];
  return Q * B * Q.transpose();
}

}  // namespace shellmpm

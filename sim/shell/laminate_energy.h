// Laminate energy of one layer of a Kirchhoff-Love shell (Guo et al. 2018, supplement
// secs. 3-4: Hencky energy of the in-plane stretch, plus our large-stretch term,
// kirchhoff_love.h), its gradient in the metric, and the log stretches for statistics.
// Internal to sim/shell (kirchhoff_love*.cpp).
#pragma once
#include <algorithm>
#include <cmath>

namespace shellmpm::kl {

/// atanh(x) / x for x in [0, 1).
template <class T>
inline T atanh_over_x(T x) {
  if (x < T(1e-2)) {
    const T x2 = x * x;
    return T(1) + x2 * (T(1) / T(3) + x2 * (T(1) / T(5) + x2 * (T(1) / T(7))));
  }
  return std::atanh(x) / x;
}

/// The elastic block's metric C = Bp^T M Bp (M = [m11 m12; m12 m22], the deformed metric;
/// columns of Bp: (Bp[0], Bp[2]) and (Bp[1], Bp[3])), its three distinct entries.
template <class T>
inline void layer_metric(const T* Bp, T m11, T m12, T m22, T& c11, T& c12, T& c22) {
  const T b00 = Bp[0], b01 = Bp[1], b10 = Bp[2], b11 = Bp[3];
  const T mb0x = m11 * b00 + m12 * b10, mb0y = m12 * b00 + m22 * b10;
  const T mb1x = m11 * b01 + m12 * b11, mb1y = m12 * b01 + m22 * b11;
  c11 = b00 * mb0x + b10 * mb0y;
  c12 = b00 * mb1x + b10 * mb1y;
  c22 = b01 * mb1x + b11 * mb1y;
}

/// dpsi/dM = Bp S_C Bp^T from dpsi/dC = [s11 s12; s12 s22] (Bp row-major): S = (S_11,
/// S_12, S_22). T may be a scalar or a lane vector (sim/shell/kl_batch.cpp).
template <class T>
inline void metric_adjoint(const T* Bp, T s11, T s12, T s22, T* S) {
  const T b00 = Bp[0], b01 = Bp[1], b10 = Bp[2], b11 = Bp[3];
  const T r00 = b00 * s11 + b01 * s12, r01 = b00 * s12 + b01 * s22;
  const T r10 = b10 * s11 + b11 * s12, r11 = b10 * s12 + b11 * s22;
  S[0] = r00 * b00 + r01 * b01;
  S[1] = r00 * b10 + r01 * b11;
  S[2] = r10 * b10 + r11 * b11;
}

/// The denting return inside the energy (KirchhoffLoveShellT::set_plasticity_in_energy):
/// the bounds of the sums and differences of the log stretches that denting.h's return
/// mapping clamps to, sum_max = sigma_y / (mu + lambda) and diff_max = sigma_y / (sqrt(3) mu).
template <class T>
struct LayerYield {
  T sum_max, diff_max;
};

/// Huber's function k x^2 / 2 for |x| <= m, k m (|x| - m / 2) beyond: the least of
/// k (x - p)^2 / 2 + k m |p| over a plastic part p, whose derivative k clamp(x, -m, m) is
/// the returned stress.
template <class T>
inline T huber(T k, T x, T m) {
  const T ax = std::abs(x);
  return ax <= m ? T(0.5) * k * x * x : k * m * (ax - T(0.5) * m);
}

/// Laminate energy density of one layer (supplement secs. 3-4) from the current metric
/// M = [g_a . g_b] (m11, m12, m22) and Bp (row-major 2x2): C = Bp^T M Bp has eigenvalues
/// s_a^2 and psi = mu/4 |log C|^2 + lambda/8 (log det C)^2 = mu |log s|^2 +
/// lambda/2 (tr log s)^2, plus the large-stretch term k sum_a (s_a - s_l)_+^2 (our addition,
/// kirchhoff_love.h). If S != nullptr writes dpsi/dM (s11, s12, s22; symmetric,
/// dpsi = sum_ab S_ab dM_ab).
/// log C = alpha I + beta C with beta = (log c1 - log c2) / (c1 - c2) evaluated as
/// 2 atanh(x) / (x tr), x = (c1 - c2) / (c1 + c2), which is stable at c1 = c2, and
/// dpsi/dC = C^-1 (mu/2 log C + lambda/4 log det C I).
/// The stretch term is a spectral function of C: with g_a = dpsi_s/dc_a = k (s_a - s_l)_+ /
/// s_a, its gradient is g_1 P_1 + g_2 P_2 = a I + b C, b = (g_1 - g_2) / (c_1 - c_2),
/// a = g_2 - b c_2. Both s_a > s_l: b = k s_l / (s_1 s_2 (s_1 + s_2)) exactly (no
/// cancellation at s_1 = s_2). Only s_1 > s_l >= s_2: c_1 - c_2 = 2h >= s_1^2 - s_l^2 > 0.
/// yield (optional): the Hencky part beyond its bounds is the return's incremental
/// potential (LayerYield, huber).
template <class T, class Stiffening>
inline T layer_psi(T mu, T lambda, const Stiffening& st, const T* Bp, T m11, T m12, T m22, T* S,
                   const LayerYield<T>* yield = nullptr) {
  T c11, c12, c22;
  layer_metric(Bp, m11, m12, m22, c11, c12, c22);
  const T tr = c11 + c22;
  const T det = c11 * c22 - c12 * c12;
  const T hd = T(0.5) * (c11 - c22);
  const T h = std::sqrt(hd * hd + c12 * c12);
  const T x = T(2) * h / tr;
  const T q = atanh_over_x(x);
  const T L = std::log(det);  // log c1 + log c2
  const T D = T(2) * x * q;   // log c1 - log c2
  T psi = T(0.125) * mu * (L * L + D * D) + T(0.125) * lambda * L * L;
  // With the return inside the energy, beyond a bound the Hencky part is the incremental
  // potential: with Sum = l_1 + l_2 = L / 2 and Diff = l_1 - l_2 = D / 2, Hencky is
  // (mu + lambda) Sum^2 / 2 + mu Diff^2 / 2, and each term becomes Huber's function of
  // its bound (denting.h clamps Sum and Diff separately). Its derivatives in
  // (L, D): a_L = (mu + lambda) clamp(Sum) / 2, a_D = mu clamp(Diff) / 2.
  const bool yielding =
      yield && (std::abs(T(0.5) * L) > yield->sum_max || T(0.5) * D > yield->diff_max);
  if (yielding)
    psi = huber(mu + lambda, T(0.5) * L, yield->sum_max) + huber(mu, T(0.5) * D, yield->diff_max);
  // Large-stretch term; l1 = log s1 >= l2 = log s2. Untaken below the limit (bitwise Hencky).
  const bool beyond = T(0.25) * (L + D) > st.log_limit;
  T stretch_i = 0, stretch_c = 0;  // its gradient in C: stretch_i I + stretch_c C
  if (beyond) {
    const T s1 = std::exp(T(0.25) * (L + D)), s2 = std::exp(T(0.25) * (L - D));
    const T d1 = std::max(s1 - st.limit, T(0));
    const T g1 = st.k * d1 / s1;
    if (s2 > st.limit) {
      const T d2 = s2 - st.limit;
      psi += st.k * (d1 * d1 + d2 * d2);
      stretch_c = st.k * st.limit / (s1 * s2 * (s1 + s2));
      stretch_i = st.k * d2 / s2 - stretch_c * s2 * s2;
    } else {
      psi += st.k * d1 * d1;
      stretch_c = d1 > T(0) ? g1 / (T(2) * h) : T(0);  // d1 > 0 here implies s1 > s2, h > 0
      stretch_i = -stretch_c * s2 * s2;
    }
  }
  if (S) {
    const T beta = T(2) * q / tr;
    const T alpha = T(0.5) * (L - beta * tr);
    T k = (T(0.5) * mu * alpha + T(0.25) * lambda * L) / det;
    T d = T(0.5) * mu * beta;
    if (yielding) {
      // dpsi/dC = C^-1 (a_L I + a_D (P_1 - P_2)), P_1 - P_2 = (C - tr / 2 I) / h; below
      // the Diff bound a_D / h = mu beta / 2 as in Hencky (h may be 0 there).
      const T sum = std::clamp(T(0.5) * L, -yield->sum_max, yield->sum_max);
      const T aL = T(0.5) * (mu + lambda) * sum;
      d = T(0.5) * D > yield->diff_max ? T(0.5) * mu * yield->diff_max / h : T(0.5) * mu * beta;
      k = (aL - T(0.5) * d * tr) / det;
    }
    // dpsi/dC = k adj(C) + d I (+ stretch_i I + stretch_c C beyond the limit)
    T s11 = k * c22 + d, s12 = -k * c12, s22 = k * c11 + d;
    if (beyond) {
      s11 += stretch_i + stretch_c * c11;
      s12 += stretch_c * c12;
      s22 += stretch_i + stretch_c * c22;
    }
    metric_adjoint(Bp, s11, s12, s22, S);
  }
  return psi;
}

/// Log singular values (log s1, log s2) of the elastic block (for statistics).
template <class T>
inline void layer_log_s(const T* Bp, T m11, T m12, T m22, T& l1, T& l2) {
  T c11, c12, c22;
  layer_metric(Bp, m11, m12, m22, c11, c12, c22);
  const T tr = c11 + c22;
  const T hd = T(0.5) * (c11 - c22);
  const T x = T(2) * std::sqrt(hd * hd + c12 * c12) / tr;
  const T L = std::log(c11 * c22 - c12 * c12);
  const T D = T(2) * x * atanh_over_x(x);
  l1 = T(0.25) * (L + D);
  l2 = T(0.25) * (L - D);
}

template <class T>
inline void mul2(const T* A, const T* B, T* out) {  // row-major 2x2 product
  out[0] = A[0] * B[0] + A[1] * B[2];
  out[1] = A[0] * B[1] + A[1] * B[3];
  out[2] = A[2] * B[0] + A[3] * B[2];
  out[3] = A[2] * B[1] + A[3] * B[3];
}

}  // namespace shellmpm::kl

// Fast 3x3 singular value decomposition and polar decomposition, float and double.
//
// Method. After McAdams, Selle, Tamstorf, Teran, Sifakis 2011, "Computing the Singular
// Value Decomposition of 3x3 matrices with minimal branching and elementary floating
// point operations" (UW-Madison TR1690): Jacobi rotations to find V, sorting with sign
// fixes, and a Givens QR of A V to find U. Written here as:
//   1. Scale A by 1 / max|a_ij| so the squared column norms used below stay far from
//      overflow and underflow for any finite input.
//   2. One-sided (Hestenes) cyclic Jacobi on B = A V: rotate pairs of columns of B (and
//      V) until they are mutually orthogonal. This is the paper's Jacobi eigenanalysis of
//      A^T A (its section 2), but the pivots (|b_p|^2, |b_q|^2, b_p . b_q) are recomputed
//      from the current columns instead of updating an explicit A^T A. That keeps the
//      backward error at a few eps |A| even when the singular values are far apart;
//      forming A^T A loses the small ones to eps |A|^2 / sigma.
//      Each rotation uses the exact symmetric Schur angle (Golub & Van Loan, Matrix
//      Computations, 4th ed., Alg. 8.5.1 "symSchur2"): tan(2 theta) = 2 gamma / (beta -
//      alpha), |theta| <= pi/4, evaluated without trigonometry as the normalized vector
//      (|d| + h, 2 sign(d) gamma) with d = beta - alpha, h = sqrt(d^2 + 4 gamma^2); its
//      squared length is 2 h (|d| + h), so one sqrt gives h and one 1/sqrt normalizes.
//      We tried the paper's cheaper approximate rotation (one inverse square root, a fixed
//      pi/4 step when the pivot is nearly degenerate): per rotation it is ~25% faster
//      here but needs 6 sweeps instead of 4 for machine precision on clustered singular
//      values, so the exact angle wins. Four sweeps reach machine precision in float and
//      double on every case in tests/sim/math/test_svd3.cpp (repeated, clustered, zero and
//      negative singular values; in float three sweeps fail there) and on 3 million
//      adversarial double-precision cases tried during development (worst reconstruction
//      error 19 eps); there is no data-dependent loop or branch, only selects.
//   3. Sort the columns of B and V by decreasing norm with conditional swaps; each swap
//      negates one column so det V stays +1 and B = A V still holds (paper, section 3).
//   4. QR of B by three Givens rotations (paper, section 4): B = U R. R is diagonal up
//      to rounding because the columns of B are orthogonal, so sigma = diag(R). Each
//      rotation leaves a non-negative entry on the diagonal, so R_00, R_11 >= 0 and only
//      sigma_2 carries the sign of det A. Zero columns (rank-deficient A) are caught by
//      the guards: U is then any rotation that completes the basis.
// Result: the "signed" SVD used by MPM (Irving et al. 2004; Stomakhin et al. 2012):
// A = U diag(sigma) V^T with U, V proper rotations (det +1), |sigma_0| >= |sigma_1| >=
// |sigma_2|, sigma_0, sigma_1 >= 0, and sigma_2 < 0 when det A < 0 (inverted).
//
// Cost. The rotations form one long chain of dependent square roots and divisions, so a
// single call is bound by their latency (see bench/svd_bench.cpp for figures). The same
// core also runs on Eigen packets: svd3_batch() does several independent matrices per
// call, one per SIMD lane, and is several times faster per matrix. Use it in loops over
// particles where the callers can be batched.
#pragma once
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <type_traits>

#if defined(__GNUC__) || defined(__clang__)
#define SHELLMPM_SVD3_INLINE inline __attribute__((always_inline))
#else
#define SHELLMPM_SVD3_INLINE inline
#endif

namespace shellmpm {
namespace detail {

// Lane abstraction: the algorithm below is written once for a "lane" type L, either a
// scalar (float, double: one matrix) or SvdPack (K SIMD packets of Eigen's packet type:
// one independent matrix per SIMD lane). Comparisons give bool for scalars and a mask
// packet for packs; SvdLane<L>::select picks per lane.
template <class L>
struct SvdLane {
  using Scalar = L;
  static constexpr int kWidth = 1;
  static SHELLMPM_SVD3_INLINE L constant(Scalar x) { return x; }
  static SHELLMPM_SVD3_INLINE L abs(L x) { return std::abs(x); }
  static SHELLMPM_SVD3_INLINE L sqrt(L x) { return std::sqrt(x); }
  static SHELLMPM_SVD3_INLINE L max(L a, L b) { return std::max(a, b); }
  static SHELLMPM_SVD3_INLINE L select(bool c, L a, L b) { return c ? a : b; }
};

/// K SIMD packets of scalar T treated as one value per lane.
template <class T, int K>
struct SvdPack {
  using P = typename Eigen::internal::packet_traits<T>::type;
  static constexpr int kPacketSize = Eigen::internal::unpacket_traits<P>::size;
  P p[K];
};
/// Per-lane comparison result of SvdPack (all-ones / all-zeros bit masks).
template <class T, int K>
struct SvdMask {
  typename SvdPack<T, K>::P m[K];
};

#define SHELLMPM_SVD3_PACK_BINOP(OP, FN)                                                           \
  template <class T, int K>                                                                        \
  SHELLMPM_SVD3_INLINE SvdPack<T, K> operator OP(const SvdPack<T, K>& a, const SvdPack<T, K>& b) { \
    SvdPack<T, K> r;                                                                               \
    for (int i = 0; i < K; ++i) r.p[i] = Eigen::internal::FN(a.p[i], b.p[i]);                      \
    return r;                                                                                      \
  }                                                                                                \
  template <class T, int K>                                                                        \
  SHELLMPM_SVD3_INLINE SvdPack<T, K> operator OP(T a, const SvdPack<T, K>& b) {                    \
    SvdPack<T, K> r;                                                                               \
    const auto pa = Eigen::internal::pset1<typename SvdPack<T, K>::P>(a);                          \
    for (int i = 0; i < K; ++i) r.p[i] = Eigen::internal::FN(pa, b.p[i]);                          \
    return r;                                                                                      \
  }
SHELLMPM_SVD3_PACK_BINOP(+, padd)
SHELLMPM_SVD3_PACK_BINOP(-, psub)
SHELLMPM_SVD3_PACK_BINOP(*, pmul)
SHELLMPM_SVD3_PACK_BINOP(/, pdiv)
#undef SHELLMPM_SVD3_PACK_BINOP

template <class T, int K>
SHELLMPM_SVD3_INLINE SvdPack<T, K> operator-(const SvdPack<T, K>& a) {
  SvdPack<T, K> r;
  for (int i = 0; i < K; ++i) r.p[i] = Eigen::internal::pnegate(a.p[i]);
  return r;
}
template <class T, int K>
SHELLMPM_SVD3_INLINE SvdMask<T, K> operator<(const SvdPack<T, K>& a, const SvdPack<T, K>& b) {
  SvdMask<T, K> r;
  for (int i = 0; i < K; ++i) r.m[i] = Eigen::internal::pcmp_lt(a.p[i], b.p[i]);
  return r;
}
template <class T, int K>
SHELLMPM_SVD3_INLINE SvdMask<T, K> operator<(const SvdPack<T, K>& a, T b) {
  SvdMask<T, K> r;
  const auto pb = Eigen::internal::pset1<typename SvdPack<T, K>::P>(b);
  for (int i = 0; i < K; ++i) r.m[i] = Eigen::internal::pcmp_lt(a.p[i], pb);
  return r;
}
template <class T, int K>
SHELLMPM_SVD3_INLINE SvdMask<T, K> operator>(const SvdPack<T, K>& a, T b) {
  SvdMask<T, K> r;
  const auto pb = Eigen::internal::pset1<typename SvdPack<T, K>::P>(b);
  for (int i = 0; i < K; ++i) r.m[i] = Eigen::internal::pcmp_lt(pb, a.p[i]);
  return r;
}
template <class T, int K>
SHELLMPM_SVD3_INLINE SvdMask<T, K> operator>=(const SvdPack<T, K>& a, T b) {
  SvdMask<T, K> r;
  const auto pb = Eigen::internal::pset1<typename SvdPack<T, K>::P>(b);
  for (int i = 0; i < K; ++i) r.m[i] = Eigen::internal::pcmp_le(pb, a.p[i]);
  return r;
}

template <class T, int K>
struct SvdLane<SvdPack<T, K>> {
  using L = SvdPack<T, K>;
  using P = typename L::P;
  using Scalar = T;
  static constexpr int kWidth = K * L::kPacketSize;
  static SHELLMPM_SVD3_INLINE L constant(Scalar x) {
    L r;
    for (int i = 0; i < K; ++i) r.p[i] = Eigen::internal::pset1<P>(x);
    return r;
  }
  static SHELLMPM_SVD3_INLINE L abs(const L& x) {
    L r;
    for (int i = 0; i < K; ++i) r.p[i] = Eigen::internal::pabs(x.p[i]);
    return r;
  }
  static SHELLMPM_SVD3_INLINE L sqrt(const L& x) {
    L r;
    for (int i = 0; i < K; ++i) r.p[i] = Eigen::internal::psqrt(x.p[i]);
    return r;
  }
  static SHELLMPM_SVD3_INLINE L max(const L& a, const L& b) {
    L r;
    for (int i = 0; i < K; ++i) r.p[i] = Eigen::internal::pmax(a.p[i], b.p[i]);
    return r;
  }
  static SHELLMPM_SVD3_INLINE L select(const SvdMask<T, K>& c, const L& a, const L& b) {
    L r;
    for (int i = 0; i < K; ++i) r.p[i] = Eigen::internal::pselect(c.m[i], a.p[i], b.p[i]);
    return r;
  }
};

/// Per-precision constants of svd3.
template <class T>
struct Svd3Traits;
template <>
struct Svd3Traits<float> {
  static constexpr int kSweeps = 4;        ///< cyclic Jacobi sweeps (3 rotations each)
  static constexpr float kTiny = 1e-18f;   ///< pivot scale below which no rotation is done
  static constexpr float kTiny2 = 1e-36f;  ///< squared-norm guard of the Givens QR
};
template <>
struct Svd3Traits<double> {
  static constexpr int kSweeps = 4;
  static constexpr double kTiny = 1e-150;
  static constexpr double kTiny2 = 1e-300;
};

/// One exact Jacobi rotation of columns p, q of b (b[col][row], A scaled to max 1),
/// accumulated into v: [b_p b_q] <- [b_p b_q] [[c, s], [-s, c]], making b_p . b_q = 0.
template <class L, int p, int q>
SHELLMPM_SVD3_INLINE void svd3_rotate_columns(L (&b)[3][3], L (&v)[3][3]) {
  using Ops = SvdLane<L>;
  using T = typename Ops::Scalar;
  const L alpha = b[p][0] * b[p][0] + b[p][1] * b[p][1] + b[p][2] * b[p][2];
  const L beta = b[q][0] * b[q][0] + b[q][1] * b[q][1] + b[q][2] * b[q][2];
  const L gamma = b[p][0] * b[q][0] + b[p][1] * b[q][1] + b[p][2] * b[q][2];
  const L d = beta - alpha;
  const L h = Ops::sqrt(d * d + T(4) * gamma * gamma);
  // (c0, s0) = (|d| + h, 2 sign(d) gamma) points along (cos theta, sin theta); its
  // squared length is 2 h (|d| + h). A negligible pivot (both columns ~0) gets no turn.
  const auto negligible = h < Svd3Traits<T>::kTiny;
  const L c0 = Ops::abs(d) + h;
  const L s0 = Ops::select(d >= T(0), T(2) * gamma, T(-2) * gamma);
  const L len2 = Ops::select(negligible, Ops::constant(T(1)), T(2) * h * c0);
  const L w = T(1) / Ops::sqrt(len2);
  const L c = Ops::select(negligible, Ops::constant(T(1)), c0 * w);
  const L s = Ops::select(negligible, Ops::constant(T(0)), s0 * w);
  for (int k = 0; k < 3; ++k) {
    const L x = b[p][k], y = b[q][k];
    b[p][k] = c * x - s * y;
    b[q][k] = s * x + c * y;
  }
  for (int k = 0; k < 3; ++k) {
    const L x = v[p][k], y = v[q][k];
    v[p][k] = c * x - s * y;
    v[q][k] = s * x + c * y;
  }
}

/// If |b_i| < |b_j| (squared norms rho), swap columns i and j of b and v and negate
/// the new column j (keeps det v = +1 and b = a v).
template <class L, int i, int j>
SHELLMPM_SVD3_INLINE void svd3_sort_pair(L (&b)[3][3], L (&v)[3][3], L (&rho)[3]) {
  using Ops = SvdLane<L>;
  const auto sw = rho[i] < rho[j];
  for (int k = 0; k < 3; ++k) {
    const L bi = b[i][k], bj = b[j][k];
    b[i][k] = Ops::select(sw, bj, bi);
    b[j][k] = Ops::select(sw, -bi, bj);
    const L vi = v[i][k], vj = v[j][k];
    v[i][k] = Ops::select(sw, vj, vi);
    v[j][k] = Ops::select(sw, -vi, vj);
  }
  const L ri = rho[i], rj = rho[j];
  rho[i] = Ops::select(sw, rj, ri);
  rho[j] = Ops::select(sw, ri, rj);
}

/// Givens rotation of rows p, q of b (b[col][row]) that zeroes b[col][q] and leaves
/// b[col][p] = hypot >= 0; accumulated into u (u[col][row]) as u <- u G^T.
template <class L, int col, int p, int q>
SHELLMPM_SVD3_INLINE void svd3_givens_rows(L (&b)[3][3], L (&u)[3][3]) {
  using Ops = SvdLane<L>;
  using T = typename Ops::Scalar;
  const L a1 = b[col][p], a2 = b[col][q];
  const L r2 = a1 * a1 + a2 * a2;
  const auto negligible = r2 < Svd3Traits<T>::kTiny2;
  const L w = T(1) / Ops::sqrt(Ops::select(negligible, Ops::constant(T(1)), r2));
  const L c = Ops::select(negligible, Ops::constant(T(1)), a1 * w);
  const L s = Ops::select(negligible, Ops::constant(T(0)), a2 * w);
  for (int j = 0; j < 3; ++j) {
    const L x = b[j][p], y = b[j][q];
    b[j][p] = c * x + s * y;
    b[j][q] = c * y - s * x;
  }
  for (int k = 0; k < 3; ++k) {
    const L x = u[p][k], y = u[q][k];
    u[p][k] = c * x + s * y;
    u[q][k] = c * y - s * x;
  }
}

/// The whole algorithm on lanes. a_in: input (a_in[col][row]); outputs u_out, v_out
/// (u[col][row]) and sigma_out. Works on local copies so that the compiler can keep
/// everything in registers whether or not the call is inlined (it is large, so it is not
/// forced inline; a call costs nothing next to its latency).
template <class L>
inline void svd3_lanes(const L (&a_in)[3][3], L (&u_out)[3][3], L (&sigma_out)[3],
                       L (&v_out)[3][3]) {
  using Ops = SvdLane<L>;
  using T = typename Ops::Scalar;
  L a[3][3], u[3][3], v[3][3];
  // 1. Scale so max |a_ij| = 1 (a zero matrix is left as is).
  L m = Ops::abs(a_in[0][0]);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) m = Ops::max(m, Ops::abs(a_in[j][i]));
  const L mm = Ops::select(m > std::numeric_limits<T>::min(), m, Ops::constant(T(1)));
  const L scale = T(1) / mm;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      a[j][i] = a_in[j][i] * scale;
      v[j][i] = Ops::constant(i == j ? T(1) : T(0));
      u[j][i] = Ops::constant(i == j ? T(1) : T(0));
    }

  // 2. One-sided Jacobi, fixed number of cyclic sweeps.
  for (int sweep = 0; sweep < Svd3Traits<T>::kSweeps; ++sweep) {
    svd3_rotate_columns<L, 0, 1>(a, v);
    svd3_rotate_columns<L, 0, 2>(a, v);
    svd3_rotate_columns<L, 1, 2>(a, v);
  }

  // 3. Sort by decreasing column norm, keeping det V = +1.
  L rho[3];
  for (int j = 0; j < 3; ++j) rho[j] = a[j][0] * a[j][0] + a[j][1] * a[j][1] + a[j][2] * a[j][2];
  svd3_sort_pair<L, 0, 1>(a, v, rho);
  svd3_sort_pair<L, 0, 2>(a, v, rho);
  svd3_sort_pair<L, 1, 2>(a, v, rho);

  // 4. QR by Givens: B = U R, sigma = diag(R) (only R_22 can be negative).
  svd3_givens_rows<L, 0, 0, 1>(a, u);
  svd3_givens_rows<L, 0, 0, 2>(a, u);
  svd3_givens_rows<L, 1, 1, 2>(a, u);
  for (int j = 0; j < 3; ++j) {
    sigma_out[j] = a[j][j] * mm;
    for (int i = 0; i < 3; ++i) {
      u_out[j][i] = u[j][i];
      v_out[j][i] = v[j][i];
    }
  }
}

}  // namespace detail

/// Signed singular value decomposition of a 3x3 matrix: A = U diag(sigma) V^T.
/// @param A      input, any finite matrix (may be inverted, singular or zero).
/// @param U, V   outputs: proper rotations (orthonormal, det = +1).
/// @param sigma  output: |sigma_0| >= |sigma_1| >= |sigma_2| (up to rounding);
///               sigma_0, sigma_1 >= 0; sigma_2 < 0 iff det A < 0.
/// Accuracy: |U diag(sigma) V^T - A| and |U^T U - I| within a few eps (relative to |A|).
template <class T>
inline void svd3(const Eigen::Matrix<T, 3, 3>& A, Eigen::Matrix<T, 3, 3>& U,
                 Eigen::Matrix<T, 3, 1>& sigma, Eigen::Matrix<T, 3, 3>& V) {
  static_assert(std::is_floating_point<T>::value, "svd3 needs float or double");
  T a[3][3], u[3][3], v[3][3], s[3];
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) a[j][i] = A(i, j);
  detail::svd3_lanes<T>(a, u, s, v);
  for (int j = 0; j < 3; ++j) {
    sigma(j) = s[j];
    for (int i = 0; i < 3; ++i) {
      U(i, j) = u[j][i];
      V(i, j) = v[j][i];
    }
  }
}

namespace detail {
/// Lane type of svd3_batch: two SIMD registers, so that two independent chains of
/// square roots interleave (4 floats each with SSE, 8 with AVX).
template <class T>
using Svd3BatchLane = SvdPack<T, 2>;
}  // namespace detail

/// Matrices per svd3_batch pass for scalar type T.
template <class T>
constexpr int svd3_batch_width() {
  return detail::SvdLane<detail::Svd3BatchLane<T>>::kWidth;
}

/// svd3 of n independent matrices: A[i] = U[i] diag(sigma[i]) V[i]^T, with the same
/// conventions and (up to rounding) the same results as svd3. Works on
/// svd3_batch_width<T>() matrices per pass, one per SIMD lane, and pads the tail with
/// zeros. U, sigma, V must hold n entries each; any of them may be nullptr to skip it.
template <class T>
inline void svd3_batch(const Eigen::Matrix<T, 3, 3>* A, std::size_t n, Eigen::Matrix<T, 3, 3>* U,
                       Eigen::Matrix<T, 3, 1>* sigma, Eigen::Matrix<T, 3, 3>* V) {
  static_assert(std::is_floating_point<T>::value, "svd3_batch needs float or double");
  using L = detail::Svd3BatchLane<T>;
  using P = typename L::P;
  constexpr int W = detail::SvdLane<L>::kWidth;
  constexpr int PS = L::kPacketSize;
  constexpr int K = W / PS;
  alignas(64) T buf[W];
  for (std::size_t base = 0; base < n; base += W) {
    const int cnt = static_cast<int>(std::min<std::size_t>(W, n - base));
    L a[3][3], u[3][3], v[3][3], s[3];
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < W; ++k) buf[k] = k < cnt ? A[base + k](i, j) : T(0);
        for (int kk = 0; kk < K; ++kk) a[j][i].p[kk] = Eigen::internal::pload<P>(buf + kk * PS);
      }
    detail::svd3_lanes<L>(a, u, s, v);
    auto unload = [&](const L& x) {
      for (int kk = 0; kk < K; ++kk) Eigen::internal::pstore<T>(buf + kk * PS, x.p[kk]);
    };
    for (int j = 0; j < 3; ++j) {
      if (sigma) {
        unload(s[j]);
        for (int k = 0; k < cnt; ++k) sigma[base + k](j) = buf[k];
      }
      for (int i = 0; i < 3; ++i) {
        if (U) {
          unload(u[j][i]);
          for (int k = 0; k < cnt; ++k) U[base + k](i, j) = buf[k];
        }
        if (V) {
          unload(v[j][i]);
          for (int k = 0; k < cnt; ++k) V[base + k](i, j) = buf[k];
        }
      }
    }
  }
}

/// Rotation factor of the polar decomposition A = R S: R = U V^T from svd3, a proper
/// rotation (det +1) also for inverted A (then S is symmetric but indefinite).
template <class T>
inline Eigen::Matrix<T, 3, 3> polar3(const Eigen::Matrix<T, 3, 3>& A) {
  Eigen::Matrix<T, 3, 3> U, V;
  Eigen::Matrix<T, 3, 1> sigma;
  svd3(A, U, sigma, V);
  return U * V.transpose();
}

/// Polar decomposition A = R S with R = U V^T (det +1) and S = V diag(sigma) V^T
/// (symmetric; its smallest eigenvalue is negative iff det A < 0).
template <class T>
inline void polar3(const Eigen::Matrix<T, 3, 3>& A, Eigen::Matrix<T, 3, 3>& R,
                   Eigen::Matrix<T, 3, 3>& S) {
  Eigen::Matrix<T, 3, 3> U, V;
  Eigen::Matrix<T, 3, 1> sigma;
  svd3(A, U, sigma, V);
  R = U * V.transpose();
  S = V * sigma.asDiagonal() * V.transpose();
}

}  // namespace shellmpm

#undef SHELLMPM_SVD3_INLINE

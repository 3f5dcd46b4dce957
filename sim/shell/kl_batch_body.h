// The Kirchhoff-Love energy and adjoints of W quadrature points at once, in float: the
// same computation as KirchhoffLoveShellT::eval_kinematics (kirchhoff_love.cpp,
// laminate_energy.h) with each point in one lane (sim/shell/kl_lanes.h). Included once by
// each translation unit of an instruction set (kl_batch.cpp: SSE, kl_batch_avx2.cpp,
// kl_batch_avx512.cpp) with SHELLMPM_KL_BATCH_ENTRY naming its entry point and
// SHELLMPM_KL_BATCH_WIDTH its lanes; everything else here has internal linkage, so no
// instruction set's copy of a helper can stand in for another's.
//
// The per-point gathers of a_alpha and a_alphabeta run one point at a time (a point's
// control points vary), x, y and z in the lanes of an SSE register, then 4x4 transposes
// put one point per lane; from there on every operation is element-wise, so a point's
// result depends neither on its lane, nor on the width, nor on its neighbours (the same
// bits on SSE, AVX2 and AVX-512, for any thread count). The branches of the scalar code
// (the small-x series of atanh(x)/x, the stretch term past the limit) are taken in every
// lane and selected.
//
// The sums of control points times coefficients (a_alpha, a_alphabeta; each control
// point's share of the forces) are fused multiply-adds (kl_lanes.h madd: the instruction
// on AVX2 and AVX-512, the same bits computed in double on SSE).
//
// Differences to the scalar code, all rounding: the fused multiply-adds, log is vlog (within 2
// ulp), atanh(x) is log((1 + x) / (1 - x)) / 2, and past the stretch limit the principal stretches
// come from the eigenvalues of C (s_1^2 = tr/2 + h, s_2^2 = det / s_1^2) instead of exp(L +- D)/4.
#include <algorithm>
#include <cstdint>
#include <cstring>

#include "sim/shell/kl_batch.h"
#include "sim/shell/kl_lanes.h"
#include "sim/shell/kl_patches.h"
#include "sim/shell/laminate_energy.h"

namespace shellmpm::kl {
namespace {

using lanes::any;
using lanes::join;
using lanes::madd;
using lanes::madd4;
using lanes::part;
using lanes::splat;
using lanes::V3;
using lanes::vlog;
using lanes::vmax;
using lanes::vsqrt;

/// (p[0], p[1], p[2], 0) without reading past p[2].
[[gnu::always_inline]] inline __m128 load3(const float* p) {
  const __m128 xy = _mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(p)));
  return _mm_movelh_ps(xy, _mm_load_ss(p + 2));
}

/// Rows r[j] (one point each, j < W) as four W-lane vectors: out[i] lane j = r[j][i].
template <class F>
[[gnu::always_inline]] inline void transpose_in(const __m128* r, F (&out)[4]) {
  constexpr int W = lanes::kLanes<F>;
  __m128 c[4][W / 4];
  for (int g = 0; g < W / 4; ++g) {
    __m128 r0 = r[4 * g], r1 = r[4 * g + 1], r2 = r[4 * g + 2], r3 = r[4 * g + 3];
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    c[0][g] = r0;
    c[1][g] = r1;
    c[2][g] = r2;
    c[3][g] = r3;
  }
  for (int i = 0; i < 4; ++i) out[i] = join<F>(c[i]);
}

/// layer_metric (laminate_energy.h) in lanes, with fused multiply-adds.
template <class F>
[[gnu::always_inline]] inline void metric_lanes(const F (&Bp)[4], F m11, F m12, F m22, F& c11,
                                                F& c12, F& c22) {
  const F b00 = Bp[0], b01 = Bp[1], b10 = Bp[2], b11 = Bp[3];
  const F mb0x = madd(m12, b10, m11 * b00), mb0y = madd(m22, b10, m12 * b00);
  const F mb1x = madd(m12, b11, m11 * b01), mb1y = madd(m22, b11, m12 * b01);
  c11 = madd(b10, mb0y, b00 * mb0x);
  c12 = madd(b10, mb1y, b00 * mb1x);
  c22 = madd(b11, mb1y, b01 * mb1x);
}

/// metric_adjoint (laminate_energy.h) in lanes, with fused multiply-adds.
template <class F>
[[gnu::always_inline]] inline void metric_adjoint_lanes(const F (&Bp)[4], F s11, F s12, F s22,
                                                        F (&S)[3]) {
  const F b00 = Bp[0], b01 = Bp[1], b10 = Bp[2], b11 = Bp[3];
  const F r00 = madd(b01, s12, b00 * s11), r01 = madd(b01, s22, b00 * s12);
  const F r10 = madd(b11, s12, b10 * s11), r11 = madd(b11, s22, b10 * s12);
  S[0] = madd(r01, b01, r00 * b00);
  S[1] = madd(r01, b11, r00 * b10);
  S[2] = madd(r11, b11, r10 * b10);
}

/// layer_psi (laminate_energy.h) in lanes: psi, and dpsi/dM in S.
template <class F>
[[gnu::always_inline]] inline F layer_psi_lanes(const BatchData& d, const F (&Bp)[4], F m11, F m12,
                                                F m22, F (&S)[3]) {
  using I = decltype(m11 < m11);
  const float mu = d.mu, lambda = d.lambda;
  F c11, c12, c22;
  metric_lanes(Bp, m11, m12, m22, c11, c12, c22);
  const F tr = c11 + c22;
  const F det = madd(c11, c22, -(c12 * c12));
  const F hd = splat<F>(0.5f) * (c11 - c22);
  const F h = vsqrt(madd(hd, hd, c12 * c12));
  // x = 2 h / tr; q = atanh(x) / x; D = 2 x q = log(c1 / c2); beta = 2 q / tr = D / (2 h).
  // Below x = 1e-2 q is the series 1 + x^2/3 + x^4/5 + x^6/7; above, D is
  // log((tr + 2 h) / (tr - 2 h)) (= log((1 + x) / (1 - x)), without rounding 1 +- x).
  const F inv_tr = splat<F>(1.0f) / tr;
  const F h2 = splat<F>(2.0f) * h;
  const F x = h2 * inv_tr;
  const F x2 = x * x;
  const F series = madd(
      x2, madd(x2, madd(x2, splat<F>(1.0f / 7.0f), splat<F>(1.0f / 5.0f)), splat<F>(1.0f / 3.0f)),
      splat<F>(1.0f));
  const I small = x < splat<F>(1e-2f);
  const F D_full = vlog((tr + h2) / (tr - h2));
  const F D = small ? splat<F>(2.0f) * x * series : D_full;
  const F L = vlog(det);
  F psi = madd(splat<F>(0.125f * mu), madd(L, L, D * D), splat<F>(0.125f * lambda) * (L * L));
  // dpsi/dC = k adj(C) + d I
  const F beta = small ? splat<F>(2.0f) * series * inv_tr : D_full / h2;
  const F alpha = splat<F>(0.5f) * madd(-beta, tr, L);
  const F kk = madd(splat<F>(0.5f * mu), alpha, splat<F>(0.25f * lambda) * L) / det;
  const F dd = splat<F>(0.5f * mu) * beta;
  F s11 = madd(kk, c22, dd), s12 = splat<F>(0.0f) - kk * c12, s22 = madd(kk, c11, dd);
  // The stretch term where log s_1 = (L + D) / 4 passes log s_l.
  const I beyond = splat<F>(0.25f) * (L + D) > splat<F>(d.log_limit);
  if (any(beyond)) {
    const F c1 = splat<F>(0.5f) * tr + h;
    const F s1 = vsqrt(c1), s2 = vsqrt(det / c1);
    const F lim = splat<F>(d.limit), ks = splat<F>(d.k);
    const F d1 = vmax(s1 - lim, splat<F>(0.0f));
    const F g1 = ks * d1 / s1;
    const I both = s2 > lim;
    const F d2 = s2 - lim;
    // Both past the limit.
    const F psi_b = ks * (d1 * d1 + d2 * d2);
    const F sc_b = ks * lim / (s1 * s2 * (s1 + s2));
    const F si_b = ks * d2 / s2 - sc_b * s2 * s2;
    // Only the larger.
    const F psi_o = ks * d1 * d1;
    const F sc_o = d1 > splat<F>(0.0f) ? g1 / (splat<F>(2.0f) * h) : splat<F>(0.0f);
    const F si_o = splat<F>(0.0f) - sc_o * s2 * s2;
    const F add = both ? psi_b : psi_o;
    const F sc = both ? sc_b : sc_o, si = both ? si_b : si_o;
    psi = beyond ? psi + add : psi;
    s11 = beyond ? s11 + (si + sc * c11) : s11;
    s12 = beyond ? s12 + sc * c12 : s12;
    s22 = beyond ? s22 + (si + sc * c22) : s22;
  }
  metric_adjoint_lanes(Bp, s11, s12, s22, S);
  return psi;
}

/// Adjoints (x, y, z, 0) of lanes' five vectors, one SSE register per lane:
/// G[i][j] = out[i] of lane j (a 4x4 transpose per group of four lanes).
template <class F>
[[gnu::always_inline]] inline void transpose_out(const V3<F>* const (&out)[5],
                                                 __m128 (&G)[5][lanes::kLanes<F>]) {
  constexpr int W = lanes::kLanes<F>;
  for (int i = 0; i < 5; ++i)
    for (int g = 0; g < W / 4; ++g) {
      __m128 r0 = part(out[i]->x, g), r1 = part(out[i]->y, g), r2 = part(out[i]->z, g),
             r3 = _mm_setzero_ps();
      _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
      G[i][4 * g] = r0;
      G[i][4 * g + 1] = r1;
      G[i][4 * g + 2] = r2;
      G[i][4 * g + 3] = r3;
    }
}

/// W floats from p (any alignment).
template <class F>
[[gnu::always_inline]] inline F load_lanes(const float* p) {
  F v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

/// One point per lane (lane j: point qs[j]) from its a_1, a_2, a_11, a_12, a_22 (av):
/// the energy, and where `adjoints` the adjoints of av in G (eval_kinematics). The points'
/// B and area come from the per-point arrays, or where `lanes` is not null already in
/// lanes: lanes->B[(4 l + e) Patches::kLaneBlock] and lanes->area (Patches::B_lanes).
struct RestLanes {
  const float* B;
  const float* area;
};
template <class F>
[[gnu::always_inline]] inline F point_lanes(const BatchData& d, const std::size_t* qs,
                                            const RestLanes* lanes, const V3<F> (&av)[5],
                                            bool adjoints, V3<F> (&G)[5]) {
  constexpr int W = lanes::kLanes<F>;
  const int nl = d.num_layers;
  const V3<F> a1 = av[0], a2 = av[1], a11 = av[2], a12 = av[3], a22 = av[4];
  // Kinematics (kl_kinematics.h, compute_kinematics).
  const V3<F> nrm = cross(a1, a2);
  const F inv_l = splat<F>(1.0f) / vsqrt(dot(nrm, nrm));
  const V3<F> a3 = inv_l * nrm;
  const V3<F> t1 = inv_l * (cross(a11, a2) + cross(a1, a12));
  const V3<F> t2 = inv_l * (cross(a12, a2) + cross(a1, a22));
  const V3<F> v1 = madd(-dot(a3, t1), a3, t1);
  const V3<F> v2 = madd(-dot(a3, t2), a3, t2);
  F area;
  if (lanes)
    area = load_lanes<F>(lanes->area);
  else
    for (int j = 0; j < W; ++j) area[j] = d.area[qs[j]];
  const V3<F> zero{splat<F>(0.0f), splat<F>(0.0f), splat<F>(0.0f)};
  V3<F> Ga1 = zero, Ga2 = zero, Gv1 = zero, Gv2 = zero;
  F energy = splat<F>(0.0f);
  for (int l = 0; l < nl; ++l) {
    const F xi3 = splat<F>(d.layer_xi3[l]);
    const V3<F> g1 = madd(xi3, v1, a1), g2 = madd(xi3, v2, a2);
    const F m11 = dot(g1, g1), m12 = dot(g1, g2), m22 = dot(g2, g2);
    __m128 rows[W];
    F Bp[4];
    if (lanes) {
      for (int e = 0; e < 4; ++e)
        Bp[e] = load_lanes<F>(lanes->B + std::size_t(4 * l + e) * Patches::kLaneBlock);
    } else {
      for (int j = 0; j < W; ++j) rows[j] = _mm_loadu_ps(&d.B[4 * (qs[j] * nl + l)]);
      transpose_in<F>(rows, Bp);
    }
    if (d.fp_inv) {
      F Fi[4];
      for (int j = 0; j < W; ++j) rows[j] = _mm_loadu_ps(&d.fp_inv[4 * (qs[j] * nl + l)]);
      transpose_in<F>(rows, Fi);
      const F B0 = Bp[0], B1 = Bp[1], B2 = Bp[2], B3 = Bp[3];
      Bp[0] = B0 * Fi[0] + B1 * Fi[2];
      Bp[1] = B0 * Fi[1] + B1 * Fi[3];
      Bp[2] = B2 * Fi[0] + B3 * Fi[2];
      Bp[3] = B2 * Fi[1] + B3 * Fi[3];
    }
    const F V = area * splat<F>(d.layer_w[l]);
    F S[3];
    energy = madd(V, layer_psi_lanes<F>(d, Bp, m11, m12, m22, S), energy);
    if (adjoints) {
      const F s = splat<F>(2.0f) * V;
      const V3<F> dg1 = s * madd(S[1], g2, S[0] * g1);
      const V3<F> dg2 = s * madd(S[2], g2, S[1] * g1);
      Ga1 = Ga1 + dg1;
      Ga2 = Ga2 + dg2;
      Gv1 = madd(xi3, dg1, Gv1);
      Gv2 = madd(xi3, dg2, Gv2);
    }
  }
  if (!adjoints) return energy;
  // Backpropagation through v_a = (I - a3 a3^T) m_a / l (eval_kinematics).
  const V3<F> PG1 = madd(-dot(a3, Gv1), a3, Gv1), PG2 = madd(-dot(a3, Gv2), a3, Gv2);
  const V3<F> cm1 = inv_l * PG1, cm2 = inv_l * PG2;
  V3<F> sum = dot(a3, t1) * PG1;
  sum = madd(dot(a3, Gv1), v1, sum);
  sum = madd(dot(Gv1, v1), a3, sum);
  sum = madd(dot(a3, t2), PG2, sum);
  sum = madd(dot(a3, Gv2), v2, sum);
  sum = madd(dot(Gv2, v2), a3, sum);
  const V3<F> cn = (splat<F>(0.0f) - inv_l) * sum;
  G[0] = Ga1 + (cross(a12, cm1) + cross(a22, cm2) + cross(a2, cn));
  G[1] = Ga2 + (cross(cm1, a11) + cross(cm2, a12) + cross(cn, a1));
  G[2] = cross(a2, cm1);
  G[3] = cross(cm1, a1) + cross(a2, cm2);
  G[4] = cross(cm2, a1);
  return energy;
}

/// Writes lane j's a_1 and a_2 at o[6 j ..] for j < cnt.
template <class F>
[[gnu::always_inline]] inline void store_a12(const V3<F> (&av)[5], int cnt, std::size_t stride,
                                             float* o) {
  for (int j = 0; j < cnt; ++j) {
    float* p = o + stride * std::size_t(j);
    p[0] = av[0].x[j], p[1] = av[0].y[j], p[2] = av[0].z[j];
    p[3] = av[1].x[j], p[4] = av[1].y[j], p[5] = av[1].z[j];
  }
}

/// Per-point path: points q0 .. q0 + n - 1, W at a time.
template <int W>
[[gnu::always_inline]] inline void eval_batch(const BatchData& d, std::size_t q0, std::size_t n,
                                              const float* x, float* fe, float* energy_out,
                                              float* a12_out) {
  using F = typename lanes::Width<W>::F;
  const std::size_t* const begin = d.begin;
  const int* const ctrl = d.ctrl;
  const float* const coef = d.coef;
  const std::uint32_t* const slot = d.slot;
  for (std::size_t b = q0; b < q0 + n; b += W) {
    const int cnt = static_cast<int>(std::min<std::size_t>(W, q0 + n - b));
    // Lane j: point b + j; lanes past the end repeat the last point (results unused).
    std::size_t qs[W];
    for (int j = 0; j < W; ++j) qs[j] = b + static_cast<std::size_t>(std::min(j, cnt - 1));
    // a_alpha, a_alphabeta of each point (gather_derivatives, x, y, z in the lanes of one
    // SSE register), then transposed to one point per lane.
    __m128 acc[5][W];
    for (int j = 0; j < W; ++j) {
      const std::size_t q = qs[j];
      if (j >= cnt) {
        for (int i = 0; i < 5; ++i) acc[i][j] = acc[i][cnt - 1];
        continue;
      }
      for (int i = 0; i < 5; ++i) acc[i][j] = _mm_setzero_ps();
      const __m128 x0 = load3(x + 3 * std::size_t(ctrl[begin[q]]));
      for (std::size_t e = begin[q] + 1; e < begin[q + 1]; ++e) {
        const __m128 dx = _mm_sub_ps(load3(x + 3 * std::size_t(ctrl[e])), x0);
        const float* c = &coef[5 * e];
        for (int i = 0; i < 5; ++i) acc[i][j] = madd4(_mm_set1_ps(c[i]), dx, acc[i][j]);
      }
    }
    V3<F> av[5];
    for (int i = 0; i < 5; ++i) {
      F t[4];
      transpose_in<F>(acc[i], t);
      av[i] = V3<F>{t[0], t[1], t[2]};
    }
    V3<F> out[5];
    const F energy = point_lanes<F>(d, qs, nullptr, av, fe != nullptr, out);
    for (int j = 0; j < cnt; ++j) energy_out[b - q0 + std::size_t(j)] = energy[j];
    if (a12_out) store_a12<F>(av, cnt, 6, a12_out + 6 * (b - q0));
    if (!fe) continue;
    // Each entry's share c0 Ga1 + c1 Ga2 + c2 G11 + c3 G12 + c4 G22 as in entry_shares,
    // one SSE store per entry.
    __m128 G[5][W];
    transpose_out<F>({&out[0], &out[1], &out[2], &out[3], &out[4]}, G);
    for (int j = 0; j < cnt; ++j)
      for (std::size_t e = begin[qs[j]], e1 = begin[qs[j] + 1]; e < e1; ++e) {
        const float* c = &coef[5 * e];
        __m128 share = _mm_mul_ps(_mm_set1_ps(c[0]), G[0][j]);
        for (int i = 1; i < 5; ++i) share = madd4(_mm_set1_ps(c[i]), G[i][j], share);
        _mm_storeu_ps(&fe[4 * std::size_t(slot[e])], share);
      }
  }
}

/// Patch path (sim/shell/kl_patches.h): patches p.order[i0 .. i0 + n - 1], one per lane,
/// W of one pattern and one lane block at a time (their B and area loaded from the lane
/// layout, Patches::B_lanes); energy_out[(i - i0) P + k] is point k of the patch at
/// position i. A point's a_alpha, a_alphabeta are summed over its control points in the
/// per-point path's order with the same coefficients, so they and the point's energy and
/// adjoints are the same bits on both paths; a share sums the patch's points in order.
template <int W>
[[gnu::always_inline]] inline void eval_patches(const BatchData& d, const PatchData& p,
                                                std::size_t i0, std::size_t n, const float* x,
                                                float* fe, float* energy_out, float* a12_out) {
  using F = typename lanes::Width<W>::F;
  const int P = p.points;
  for (std::size_t i = i0; i < i0 + n;) {
    const std::uint32_t pat = p.pattern[p.order[i]];
    int cnt = 1;
    // A register's patches share a pattern and a lane block (Patches::B_lanes).
    while (cnt < W && i + std::size_t(cnt) < i0 + n && p.pattern[p.order[i + cnt]] == pat &&
           (i + std::size_t(cnt)) % Patches::kLaneBlock != 0)
      ++cnt;
    // Lane j: patch order[i + j]; lanes past cnt repeat the last (results unused).
    std::uint32_t g[W];
    for (int j = 0; j < W; ++j) g[j] = p.order[i + std::size_t(std::min(j, cnt - 1))];
    const std::size_t blk = i / Patches::kLaneBlock, lane0 = i % Patches::kLaneBlock;
    const int m = static_cast<int>(p.pattern_size[pat]);
    const float* const C = p.coefs + p.pattern_coef[pat];  // [k][c][5]
    // Control positions, one patch per lane, relative to the first.
    V3<F> dX[Patches::kMaxCtrl];
    for (int c = 0; c < m; ++c) {
      __m128 rows[W];
      for (int j = 0; j < W; ++j) rows[j] = load3(x + 3 * std::size_t(p.ctrl[p.begin[g[j]] + c]));
      F t[4];
      transpose_in<F>(rows, t);
      dX[c] = V3<F>{t[0], t[1], t[2]};
      if (c > 0) dX[c] = dX[c] - dX[0];
    }
    V3<F> G[Patches::kMaxPoints][5];
    for (int k = 0; k < P; ++k) {
      const V3<F> zero{splat<F>(0.0f), splat<F>(0.0f), splat<F>(0.0f)};
      V3<F> av[5] = {zero, zero, zero, zero, zero};
      for (int c = 1; c < m; ++c) {
        const float* ck = C + 5 * (std::size_t(k) * m + c);
        for (int a = 0; a < 5; ++a) av[a] = madd(splat<F>(ck[a]), dX[c], av[a]);
      }
      std::size_t qs[W];
      for (int j = 0; j < W; ++j) qs[j] = std::size_t(g[j]) * P + k;
      // The rest data in lanes: lanes past cnt read other patches' (finite; their results
      // are unused).
      const std::size_t row = blk * std::size_t(P) + std::size_t(k);
      const RestLanes lanes{
          p.B_lanes + row * std::size_t(4 * d.num_layers) * Patches::kLaneBlock + lane0,
          p.area_lanes + row * Patches::kLaneBlock + lane0};
      const F energy = point_lanes<F>(d, qs, &lanes, av, fe != nullptr, G[k]);
      const std::size_t o = (i - i0) * P + k;
      for (int j = 0; j < cnt; ++j) energy_out[o + std::size_t(j) * P] = energy[j];
      if (a12_out) store_a12<F>(av, cnt, 6 * std::size_t(P), a12_out + 6 * o);
    }
    if (fe) {
      // Per control point c: sum over the points k of c0 Ga1 + c1 Ga2 + c2 G11 + c3 G12 +
      // c4 G22 (one fused multiply-add per term), then one SSE store per lane.
      for (int c = 0; c < m; ++c) {
        V3<F> s = splat<F>(C[5 * std::size_t(c)]) * G[0][0];
        for (int k = 0; k < P; ++k) {
          const float* ck = C + 5 * (std::size_t(k) * m + c);
          for (int a = k == 0 ? 1 : 0; a < 5; ++a) s = madd(splat<F>(ck[a]), G[k][a], s);
        }
        for (int q = 0; q < W / 4; ++q) {
          __m128 r0 = part(s.x, q), r1 = part(s.y, q), r2 = part(s.z, q), r3 = _mm_setzero_ps();
          _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
          const __m128 r[4] = {r0, r1, r2, r3};
          for (int j = 0; j < 4 && 4 * q + j < cnt; ++j)
            _mm_storeu_ps(&fe[4 * std::size_t(p.slot[p.begin[g[4 * q + j]] + c])], r[j]);
        }
      }
    }
    i += std::size_t(cnt);
  }
}

}  // namespace

__attribute__((flatten)) void SHELLMPM_KL_BATCH_ENTRY(const BatchData& d, std::size_t q0,
                                                      std::size_t n, const float* x, float* fe,
                                                      float* energy, float* a12) {
  eval_batch<SHELLMPM_KL_BATCH_WIDTH>(d, q0, n, x, fe, energy, a12);
}

__attribute__((flatten)) void SHELLMPM_KL_PATCH_ENTRY(const BatchData& d, const PatchData& p,
                                                      std::size_t i0, std::size_t n, const float* x,
                                                      float* fe, float* energy, float* a12) {
  eval_patches<SHELLMPM_KL_BATCH_WIDTH>(d, p, i0, n, x, fe, energy, a12);
}

}  // namespace shellmpm::kl

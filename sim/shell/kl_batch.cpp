// The Kirchhoff-Love energy and adjoints of four quadrature points at once, in float: the
// same computation as KirchhoffLoveShellT::eval_kinematics (kirchhoff_love.cpp,
// laminate_energy.h) with each point in one lane of an SSE register (sim/shell/kl_lanes.h).
// The per-point gathers of a_alpha and a_alphabeta run one point at a time (a point's
// control points vary), x, y and z in the lanes; from there on every operation is
// element-wise, so a point's result does not
// depend on its lane or its neighbours, and is the same for any thread count. The branches
// of the scalar code (the small-x series of atanh(x)/x, the stretch term past the limit)
// are taken in every lane and selected.
//
// Differences to the scalar code, all rounding: log is log4 (within 2 ulp), atanh(x) is
// log((1 + x) / (1 - x)) / 2, and past the stretch limit the principal stretches come from
// the eigenvalues of C (s_1^2 = tr/2 + h, s_2^2 = det / s_1^2) instead of exp(L +- D)/4.
#include <algorithm>
#include <cstdint>

#include "sim/shell/kirchhoff_love.h"
#include "sim/shell/kl_kinematics.h"
#include "sim/shell/kl_lanes.h"
#include "sim/shell/laminate_energy.h"

namespace shellmpm {

using kl::lanes::F4;
using kl::lanes::I4;
using kl::lanes::splat;
using kl::lanes::V3;

namespace {

/// (p[0], p[1], p[2], 0) without reading past p[2].
[[gnu::always_inline]] inline F4 load3(const float* p) {
  const __m128 xy = _mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(p)));
  return reinterpret_cast<F4>(_mm_movelh_ps(xy, _mm_load_ss(p + 2)));
}

/// layer_psi (laminate_energy.h) in lanes: psi, and dpsi/dM in S.
template <class Stiffening>
F4 layer_psi4(float mu, float lambda, const Stiffening& st, const F4 (&Bp)[4], F4 m11, F4 m12,
              F4 m22, F4 (&S)[3]) {
  using namespace kl::lanes;
  F4 c11, c12, c22;
  kl::layer_metric(Bp, m11, m12, m22, c11, c12, c22);
  const F4 tr = c11 + c22;
  const F4 det = c11 * c22 - c12 * c12;
  const F4 hd = splat(0.5f) * (c11 - c22);
  const F4 h = sqrt4(hd * hd + c12 * c12);
  const F4 x = splat(2.0f) * h / tr;
  // atanh(x) / x: the series below 1e-2, else log((1 + x) / (1 - x)) / (2 x).
  const F4 x2 = x * x;
  const F4 series =
      splat(1.0f) + x2 * (splat(1.0f / 3.0f) + x2 * (splat(1.0f / 5.0f) + x2 * splat(1.0f / 7.0f)));
  const F4 full = splat(0.5f) * log4((splat(1.0f) + x) / (splat(1.0f) - x)) / x;
  const F4 q = x < splat(1e-2f) ? series : full;
  const F4 L = log4(det);
  const F4 D = splat(2.0f) * x * q;
  F4 psi = splat(0.125f * mu) * (L * L + D * D) + splat(0.125f * lambda) * (L * L);
  // dpsi/dC = k adj(C) + d I
  const F4 beta = splat(2.0f) * q / tr;
  const F4 alpha = splat(0.5f) * (L - beta * tr);
  const F4 k = (splat(0.5f * mu) * alpha + splat(0.25f * lambda) * L) / det;
  const F4 d = splat(0.5f * mu) * beta;
  F4 s11 = k * c22 + d, s12 = splat(0.0f) - k * c12, s22 = k * c11 + d;
  // The stretch term where log s_1 = (L + D) / 4 passes log s_l.
  const I4 beyond = splat(0.25f) * (L + D) > splat(st.log_limit);
  if (beyond[0] | beyond[1] | beyond[2] | beyond[3]) {
    const F4 c1 = splat(0.5f) * tr + h;
    const F4 s1 = sqrt4(c1), s2 = sqrt4(det / c1);
    const F4 lim = splat(st.limit), kk = splat(st.k);
    const F4 d1 = max4(s1 - lim, splat(0.0f));
    const F4 g1 = kk * d1 / s1;
    const I4 both = s2 > lim;
    const F4 d2 = s2 - lim;
    // Both past the limit.
    const F4 psi_b = kk * (d1 * d1 + d2 * d2);
    const F4 sc_b = kk * lim / (s1 * s2 * (s1 + s2));
    const F4 si_b = kk * d2 / s2 - sc_b * s2 * s2;
    // Only the larger.
    const F4 psi_o = kk * d1 * d1;
    const F4 sc_o = d1 > splat(0.0f) ? g1 / (splat(2.0f) * h) : splat(0.0f);
    const F4 si_o = splat(0.0f) - sc_o * s2 * s2;
    const F4 add = both ? psi_b : psi_o;
    const F4 sc = both ? sc_b : sc_o, si = both ? si_b : si_o;
    psi = beyond ? psi + add : psi;
    s11 = beyond ? s11 + (si + sc * c11) : s11;
    s12 = beyond ? s12 + sc * c12 : s12;
    s22 = beyond ? s22 + (si + sc * c22) : s22;
  }
  kl::metric_adjoint(Bp, s11, s12, s22, S);
  return psi;
}

}  // namespace

template <>
void KirchhoffLoveShellT<float>::eval_points(std::size_t q0, std::size_t n, const Vec3T* x,
                                             float* fe, double& e_total, double* e_membrane) const {
  using namespace kl::lanes;
  const bool plastic = !fp_inv_.empty();
  // Local copies of the arrays' pointers: the SSE stores below may alias anything, which
  // would otherwise reload them from the object at every entry.
  const std::size_t* const begin = begin_.data();
  const int* const ctrl = ctrl_.data();
  const float* const coef = coef_.data();
  const std::uint32_t* const slot = slot_.data();
  for (std::size_t b = q0; b < q0 + n; b += 4) {
    const int cnt = static_cast<int>(std::min<std::size_t>(4, q0 + n - b));
    // Lane j: point b + j; lanes past the end repeat the last point (results unused).
    std::size_t qs[4];
    for (int j = 0; j < 4; ++j) qs[j] = b + static_cast<std::size_t>(std::min(j, cnt - 1));
    // a_alpha, a_alphabeta of each point (gather_derivatives, one SSE lane per axis), then
    // transposed to one point per lane.
    F4 acc[5][4];
    for (int j = 0; j < 4; ++j) {
      const std::size_t q = qs[j];
      if (j >= cnt) {
        for (int i = 0; i < 5; ++i) acc[i][j] = acc[i][cnt - 1];
        continue;
      }
      for (int i = 0; i < 5; ++i) acc[i][j] = splat(0.0f);
      const F4 x0 = load3(x[ctrl[begin[q]]].data());
      for (std::size_t e = begin[q] + 1; e < begin[q + 1]; ++e) {
        const F4 dx = load3(x[ctrl[e]].data()) - x0;
        const float* c = &coef[5 * e];
        for (int i = 0; i < 5; ++i) acc[i][j] = acc[i][j] + splat(c[i]) * dx;
      }
    }
    V3 av[5];
    for (int i = 0; i < 5; ++i) {
      __m128 r0 = reinterpret_cast<__m128>(acc[i][0]), r1 = reinterpret_cast<__m128>(acc[i][1]),
             r2 = reinterpret_cast<__m128>(acc[i][2]), r3 = reinterpret_cast<__m128>(acc[i][3]);
      _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
      av[i] = V3{reinterpret_cast<F4>(r0), reinterpret_cast<F4>(r1), reinterpret_cast<F4>(r2)};
    }
    const V3 a1 = av[0], a2 = av[1], a11 = av[2], a12 = av[3], a22 = av[4];
    // Kinematics (kl_kinematics.h, compute_kinematics).
    const V3 nrm = cross(a1, a2);
    const F4 inv_l = splat(1.0f) / sqrt4(dot(nrm, nrm));
    const V3 a3 = inv_l * nrm;
    const V3 t1 = inv_l * (cross(a11, a2) + cross(a1, a12));
    const V3 t2 = inv_l * (cross(a12, a2) + cross(a1, a22));
    const V3 v1 = t1 - dot(a3, t1) * a3;
    const V3 v2 = t2 - dot(a3, t2) * a3;
    const F4 area{area_[qs[0]], area_[qs[1]], area_[qs[2]], area_[qs[3]]};
    const V3 zero{splat(0.0f), splat(0.0f), splat(0.0f)};
    V3 Ga1 = zero, Ga2 = zero, Gv1 = zero, Gv2 = zero;
    F4 energy = splat(0.0f);
    for (int l = 0; l < num_layers_; ++l) {
      const F4 xi3 = splat(layer_xi3_[l]);
      const V3 g1 = a1 + xi3 * v1, g2 = a2 + xi3 * v2;
      const F4 m11 = dot(g1, g1), m12 = dot(g1, g2), m22 = dot(g2, g2);
      F4 Bp[4];
      for (int i = 0; i < 4; ++i) {
        Bp[i] = F4{B_[4 * (qs[0] * num_layers_ + l) + i], B_[4 * (qs[1] * num_layers_ + l) + i],
                   B_[4 * (qs[2] * num_layers_ + l) + i], B_[4 * (qs[3] * num_layers_ + l) + i]};
      }
      if (plastic) {
        F4 Fi[4];
        for (int i = 0; i < 4; ++i)
          Fi[i] = F4{fp_inv_[4 * (qs[0] * num_layers_ + l) + i],
                     fp_inv_[4 * (qs[1] * num_layers_ + l) + i],
                     fp_inv_[4 * (qs[2] * num_layers_ + l) + i],
                     fp_inv_[4 * (qs[3] * num_layers_ + l) + i]};
        const F4 B0 = Bp[0], B1 = Bp[1], B2 = Bp[2], B3 = Bp[3];
        Bp[0] = B0 * Fi[0] + B1 * Fi[2];
        Bp[1] = B0 * Fi[1] + B1 * Fi[3];
        Bp[2] = B2 * Fi[0] + B3 * Fi[2];
        Bp[3] = B2 * Fi[1] + B3 * Fi[3];
      }
      const F4 V = area * splat(layer_w_[l]);
      F4 S[3];
      energy = energy + V * layer_psi4(mu_, lambda_, stiffening_, Bp, m11, m12, m22, S);
      if (fe) {
        const F4 s = splat(2.0f) * V;
        const V3 dg1 = s * (S[0] * g1 + S[1] * g2);
        const V3 dg2 = s * (S[1] * g1 + S[2] * g2);
        Ga1 = Ga1 + dg1;
        Ga2 = Ga2 + dg2;
        Gv1 = Gv1 + xi3 * dg1;
        Gv2 = Gv2 + xi3 * dg2;
      }
    }
    for (int j = 0; j < cnt; ++j) {
      e_total += double(energy[j]);
      if (e_membrane)
        *e_membrane += membrane_energy(qs[j], Vec3T(a1.x[j], a1.y[j], a1.z[j]),
                                       Vec3T(a2.x[j], a2.y[j], a2.z[j]));
    }
    if (!fe) continue;
    // Backpropagation through v_a = (I - a3 a3^T) m_a / l (eval_kinematics).
    const V3 PG1 = Gv1 - dot(a3, Gv1) * a3, PG2 = Gv2 - dot(a3, Gv2) * a3;
    const V3 cm1 = inv_l * PG1, cm2 = inv_l * PG2;
    const V3 sum = dot(a3, t1) * PG1 + dot(a3, Gv1) * v1 + dot(Gv1, v1) * a3 + dot(a3, t2) * PG2 +
                   dot(a3, Gv2) * v2 + dot(Gv2, v2) * a3;
    const V3 cn = (splat(0.0f) - inv_l) * sum;
    Ga1 = Ga1 + (cross(a12, cm1) + cross(a22, cm2) + cross(a2, cn));
    Ga2 = Ga2 + (cross(cm1, a11) + cross(cm2, a12) + cross(cn, a1));
    const V3 G11 = cross(a2, cm1);
    const V3 G12 = cross(cm1, a1) + cross(a2, cm2);
    const V3 G22 = cross(cm2, a1);
    const V3* out[5] = {&Ga1, &Ga2, &G11, &G12, &G22};
    // Per point j the five adjoints as (x, y, z, 0) (a 4x4 transpose each), then each
    // entry's share c0 Ga1 + c1 Ga2 + c2 G11 + c3 G12 + c4 G22 as in entry_shares, one
    // SSE store per entry.
    F4 G[5][4];
    for (int i = 0; i < 5; ++i) {
      __m128 r0 = reinterpret_cast<__m128>(out[i]->x), r1 = reinterpret_cast<__m128>(out[i]->y),
             r2 = reinterpret_cast<__m128>(out[i]->z), r3 = _mm_setzero_ps();
      _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
      G[i][0] = reinterpret_cast<F4>(r0);
      G[i][1] = reinterpret_cast<F4>(r1);
      G[i][2] = reinterpret_cast<F4>(r2);
      G[i][3] = reinterpret_cast<F4>(r3);
    }
    for (int j = 0; j < cnt; ++j)
      for (std::size_t e = begin[qs[j]], e1 = begin[qs[j] + 1]; e < e1; ++e) {
        const float* c = &coef[5 * e];
        const F4 share = splat(c[0]) * G[0][j] + splat(c[1]) * G[1][j] + splat(c[2]) * G[2][j] +
                         splat(c[3]) * G[3][j] + splat(c[4]) * G[4][j];
        _mm_storeu_ps(&fe[4 * std::size_t(slot[e])], reinterpret_cast<__m128>(share));
      }
  }
}

}  // namespace shellmpm

// The contact sites' gradient dots eight sites at a time (sim/contact/shell_transfer.h):
// the moments of each site's stencil (moment_lanes) and, for one vector u per site,
// t_n = (d_n - dbar) . Minv^T u for its 27 nodes (SiteMoments::offsets_dot), optionally
// times a_n (SiteMoments::dot), one site per lane. The sites' G2P (u = a3E, weighted) and
// normal forces (u = a3E, unweighted) use them.
//
// The body is inlined into the shells' per-block loops, which are compiled for SSE, AVX2
// and AVX-512 (shell_blocks.h); site_dots_batch is the library's (x86-64-v2) instance.
// Every lane does the same IEEE operations as site_moments and offsets_dot on one site,
// with no contraction into fused multiply-adds, so every instance gives those bits
// (tests/sim/contact/test_site_moments.cpp; across instruction sets through the shells'
// transfers, test_contact_solver.cpp). Internal to sim/contact.
#pragma once
#include <cstring>

#include "sim/contact/shell_transfer.h"

namespace shellmpm::site_dots {

/// The dots of `in`'s first n sites (lanes n.. are overwritten with lane 0): out[k][j] for
/// node k of site j, any[j] false where no node of site j has mass (out unset there).
template <class F>
[[gnu::always_inline]] inline void dots_lanes(SiteLaneInputs& in, int n, Real dx, bool weighted,
                                              Real (&out)[27][kSiteLanes],
                                              bool (&any)[kSiteLanes]) {
  for (int j = n; j < kSiteLanes; ++j) {
    for (int a = 0; a < 3; ++a) {
      in.fx[a][j] = in.fx[a][0];
      in.u[a][j] = in.u[a][0];
      for (int o = 0; o < 3; ++o) in.w[a][o][j] = in.w[a][o][0];
    }
    for (int k = 0; k < 27; ++k) in.m[k][j] = in.m[k][0];
  }
  F w[3][3], fx[3], mm[27], u[3];
  static_assert(sizeof w == sizeof in.w && sizeof fx == sizeof in.fx && sizeof mm == sizeof in.m &&
                sizeof u == sizeof in.u);
  std::memcpy(w, in.w, sizeof w);
  std::memcpy(fx, in.fx, sizeof fx);
  std::memcpy(mm, in.m, sizeof mm);
  std::memcpy(u, in.u, sizeof u);
  MomentLanes<F> L;
  moment_lanes<F>(w, fx, mm, dx, L);
  // q = Minv^T u (Minv symmetric), as SiteMoments::offsets_dot.
  const F* m = L.minv;  // 00 01 02 11 12 22
  const F q[3] = {(m[0] * u[0] + m[1] * u[1]) + m[2] * u[2],
                  (m[1] * u[0] + m[3] * u[1]) + m[4] * u[2],
                  (m[2] * u[0] + m[4] * u[1]) + m[5] * u[2]};
  F t[27];
  int k = 0;
  for (int i = 0; i < 3; ++i) {
    const F si = L.e[0][i] * q[0];
    for (int j = 0; j < 3; ++j) {
      const F sij = si + L.e[1][j] * q[1];
      for (int l = 0; l < 3; ++l, ++k) t[k] = sij + L.e[2][l] * q[2];
    }
  }
  if (weighted)
    for (int c = 0; c < 27; ++c) t[c] = L.a[c] * t[c];
  static_assert(sizeof t == sizeof out);
  std::memcpy(out, t, sizeof t);
  for (int j = 0; j < n; ++j) any[j] = L.asum[j] > 0;
}

typedef Real Lanes __attribute__((vector_size(kSiteLanes * sizeof(Real))));

}  // namespace shellmpm::site_dots

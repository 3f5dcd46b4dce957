// contact_lanes.h's AVX-512 entry points: compiled with -march=x86-64-v4 -ffp-contract=off
// (CMakeLists.txt): every a * b + c keeps its two roundings.
#include <immintrin.h>

#include "sim/contact/contact_lanes.h"

SHELLMPM_CONTACT_LANES_ENTRIES(avx512)

namespace shellmpm::contact_lanes {

void stencils_avx512(const SiteStencils& s, std::size_t p0, std::size_t n) {
  static_assert(sizeof(Vec3) == 3 * sizeof(float) && sizeof(Real) == sizeof(float));
  // Lanes 0-3: the position's sum, 4-7: a1's, 8-11: a2's, each over (x, y, z, 0) as in
  // ShellContact::position_and_tangents: d += N (c - ref), one rounding per product and
  // one per sum, in stencil order. Loads of three floats are masked (nothing past them is
  // read).
  const __m512i spread = _mm512_set_epi32(3, 3, 3, 3, 2, 2, 2, 2, 1, 1, 1, 1, 0, 0, 0, 0);
  for (std::size_t p = p0; p < p0 + n; ++p) {
    const std::uint32_t k0 = s.off[p], k1 = s.off[p + 1];
    const float* w = s.table + 3 * static_cast<std::size_t>(s.row[p]);
    const __m128 ref = _mm_maskz_loadu_ps(0x7, s.ctrl[s.idx[k0]].data());
    __m512 acc = _mm512_setzero_ps();
    for (std::uint32_t k = k0; k < k1; ++k, w += 3) {
      const __m128 dk = _mm_sub_ps(_mm_maskz_loadu_ps(0x7, s.ctrl[s.idx[k]].data()), ref);
      const __m512 W =
          _mm512_permutexvar_ps(spread, _mm512_castps128_ps512(_mm_maskz_loadu_ps(0x7, w)));
      acc = _mm512_add_ps(acc, _mm512_mul_ps(W, _mm512_broadcast_f32x4(dk)));
    }
    _mm_mask_storeu_ps(s.x[p].data(), 0x7, _mm_add_ps(ref, _mm512_castps512_ps128(acc)));
    _mm_mask_storeu_ps(s.a1[p].data(), 0x7, _mm512_extractf32x4_ps(acc, 1));
    _mm_mask_storeu_ps(s.a2[p].data(), 0x7, _mm512_extractf32x4_ps(acc, 2));
  }
}

}  // namespace shellmpm::contact_lanes

// One row of a point's 3x3x3 stencil as a short vector: the three nodes (i, j, 0..2) of a
// padded particle-block buffer, each (m, v0, v1, v2), so twelve scalars. The transfers
// (sim/mpm/apic_stencil.h) do all their per-node arithmetic on rows: one AVX-512 register
// where the translation unit is compiled for it (sim/mpm/transfer_blocks.h), three SSE
// registers otherwise, plain arrays in double builds.
//
// Every implementation does the same element-wise IEEE operations, lane by lane, with no
// contraction into fused multiply-adds: a row sum is the same bits on any instruction set.
// Each lives in its own inline namespace, so the AVX-512 functions never share a symbol
// with the SSE ones.
#pragma once
#include <immintrin.h>

#include <cstring>

#include "sim/core/types.h"
#include "sim/mpm/sparse_grid.h"

namespace shellmpm::stencil_row {

static_assert(sizeof(GridNode) == 4 * sizeof(Real), "a node is four scalars");
#define SHELLMPM_ROW_INLINE [[gnu::always_inline]] inline

#if defined(__AVX512F__) && !defined(SHELLMPM_DOUBLE)
inline namespace avx512 {
struct Row {
  __m512 r;  ///< lanes 12..15 zero
};
constexpr __mmask16 kRowMask = 0x0FFF;
SHELLMPM_ROW_INLINE Row zero() {
  return {_mm512_setzero_ps()};
}
SHELLMPM_ROW_INLINE Row load(const GridNode* p) {
  return {_mm512_maskz_loadu_ps(kRowMask, reinterpret_cast<const float*>(p))};
}
SHELLMPM_ROW_INLINE void store(GridNode* p, const Row& a) {
  _mm512_mask_storeu_ps(reinterpret_cast<float*>(p), kRowMask, a.r);
}
/// (a, b0, b1, b2) in each node.
SHELLMPM_ROW_INLINE Row splat(Real a, const Vec3& b) {
  return {_mm512_maskz_broadcast_f32x4(kRowMask, _mm_setr_ps(a, b[0], b[1], b[2]))};
}
/// n[k] in every lane of node k.
SHELLMPM_ROW_INLINE Row per_node(const Real* n) {
  const __m512 q = _mm512_castps128_ps512(_mm_setr_ps(n[0], n[1], n[2], 0));
  const __m512i idx = _mm512_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3);
  return {_mm512_maskz_permutexvar_ps(kRowMask, idx, q)};
}
SHELLMPM_ROW_INLINE Row operator+(const Row& a, const Row& b) {
  return {_mm512_add_ps(a.r, b.r)};
}
SHELLMPM_ROW_INLINE Row operator-(const Row& a, const Row& b) {
  return {_mm512_sub_ps(a.r, b.r)};
}
SHELLMPM_ROW_INLINE Row operator*(const Row& a, const Row& b) {
  return {_mm512_mul_ps(a.r, b.r)};
}
SHELLMPM_ROW_INLINE Row operator*(Real s, const Row& b) {
  return {_mm512_mul_ps(_mm512_set1_ps(s), b.r)};
}
/// out[c] = node0[c] + node1[c] + node2[c], summed in that order.
SHELLMPM_ROW_INLINE void node_sum(const Row& a, Real* out) {
  const __m128 s =
      _mm_add_ps(_mm_add_ps(_mm512_castps512_ps128(a.r), _mm512_extractf32x4_ps(a.r, 1)),
                 _mm512_extractf32x4_ps(a.r, 2));
  _mm_storeu_ps(out, s);
}
}  // namespace avx512

#elif !defined(SHELLMPM_DOUBLE)
inline namespace sse {
struct Row {
  __m128 g[3];  ///< one node each
};
SHELLMPM_ROW_INLINE Row zero() {
  return {{_mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps()}};
}
SHELLMPM_ROW_INLINE Row load(const GridNode* p) {
  const float* f = reinterpret_cast<const float*>(p);
  return {{_mm_loadu_ps(f), _mm_loadu_ps(f + 4), _mm_loadu_ps(f + 8)}};
}
SHELLMPM_ROW_INLINE void store(GridNode* p, const Row& a) {
  float* f = reinterpret_cast<float*>(p);
  _mm_storeu_ps(f, a.g[0]);
  _mm_storeu_ps(f + 4, a.g[1]);
  _mm_storeu_ps(f + 8, a.g[2]);
}
SHELLMPM_ROW_INLINE Row splat(Real a, const Vec3& b) {
  const __m128 q = _mm_setr_ps(a, b[0], b[1], b[2]);
  return {{q, q, q}};
}
SHELLMPM_ROW_INLINE Row per_node(const Real* n) {
  return {{_mm_set1_ps(n[0]), _mm_set1_ps(n[1]), _mm_set1_ps(n[2])}};
}
#define SHELLMPM_ROW_OP(op, fn)                                            \
  SHELLMPM_ROW_INLINE Row operator op(const Row& a, const Row& b) {        \
    return {{fn(a.g[0], b.g[0]), fn(a.g[1], b.g[1]), fn(a.g[2], b.g[2])}}; \
  }
SHELLMPM_ROW_OP(+, _mm_add_ps)
SHELLMPM_ROW_OP(-, _mm_sub_ps)
SHELLMPM_ROW_OP(*, _mm_mul_ps)
#undef SHELLMPM_ROW_OP
SHELLMPM_ROW_INLINE Row operator*(Real s, const Row& b) {
  const __m128 v = _mm_set1_ps(s);
  return {{_mm_mul_ps(v, b.g[0]), _mm_mul_ps(v, b.g[1]), _mm_mul_ps(v, b.g[2])}};
}
SHELLMPM_ROW_INLINE void node_sum(const Row& a, Real* out) {
  _mm_storeu_ps(out, _mm_add_ps(_mm_add_ps(a.g[0], a.g[1]), a.g[2]));
}
}  // namespace sse

#else
inline namespace scalar {
struct Row {
  Real l[12];
};
SHELLMPM_ROW_INLINE Row zero() {
  return Row{};
}
SHELLMPM_ROW_INLINE Row load(const GridNode* p) {
  Row r;
  std::memcpy(r.l, p, sizeof(r.l));
  return r;
}
SHELLMPM_ROW_INLINE void store(GridNode* p, const Row& a) {
  std::memcpy(p, a.l, sizeof(a.l));
}
SHELLMPM_ROW_INLINE Row splat(Real a, const Vec3& b) {
  Row r;
  for (int k = 0; k < 3; ++k) {
    r.l[4 * k] = a;
    for (int c = 0; c < 3; ++c) r.l[4 * k + 1 + c] = b[c];
  }
  return r;
}
SHELLMPM_ROW_INLINE Row per_node(const Real* n) {
  Row r;
  for (int q = 0; q < 12; ++q) r.l[q] = n[q / 4];
  return r;
}
#define SHELLMPM_ROW_OP(op)                                         \
  SHELLMPM_ROW_INLINE Row operator op(const Row& a, const Row& b) { \
    Row r;                                                          \
    for (int q = 0; q < 12; ++q) r.l[q] = a.l[q] op b.l[q];         \
    return r;                                                       \
  }
SHELLMPM_ROW_OP(+)
SHELLMPM_ROW_OP(-)
SHELLMPM_ROW_OP(*)
#undef SHELLMPM_ROW_OP
SHELLMPM_ROW_INLINE Row operator*(Real s, const Row& b) {
  Row r;
  for (int q = 0; q < 12; ++q) r.l[q] = s * b.l[q];
  return r;
}
SHELLMPM_ROW_INLINE void node_sum(const Row& a, Real* out) {
  for (int c = 0; c < 4; ++c) out[c] = a.l[c] + a.l[4 + c] + a.l[8 + c];
}
}  // namespace scalar
#endif

#undef SHELLMPM_ROW_INLINE
}  // namespace shellmpm::stencil_row

// Lane arithmetic for the batched Kirchhoff-Love force kernel (sim/shell/kl_batch_body.h):
// W quadrature points in one SSE (4), AVX (8) or AVX-512 (16) register, element-wise
// operators (GCC vector extensions), selects, square root, an any-lane test and a
// vectorised natural logarithm. Every operation is element-wise and exactly rounded or
// integer, so a lane's result is the same at every width. Internal to sim/shell.
//
// log: x = m 2^e with m in [sqrt(1/2), sqrt(2)), log x = e log 2 + log m, log(1 + f) by the
// degree-9 minimax polynomial of Cephes' logf (Moshier) and log 2 split in two parts
// (0.693359375 exact in float, plus -2.12194440e-4): within 2 ulp of std::log on normal
// numbers (tests/sim/shell/test_kl_batch.cpp). Zero gives -inf, negatives and NaN give
// NaN, inf gives inf, as std::log; subnormals are read as their normal neighbours' scale
// (a layer that thin has blown up long before).
//
// The 8- and 16-lane forms need the translation unit compiled for AVX2 or AVX-512: a
// width is only instantiated where its instructions are enabled.
#pragma once
#include <immintrin.h>

#include <cstdint>
#include <limits>

namespace shellmpm::kl::lanes {

template <int W>
struct Width {
  typedef float F __attribute__((vector_size(4 * W)));
  typedef std::int32_t I __attribute__((vector_size(4 * W)));
};
typedef Width<4>::F F4;
typedef Width<4>::I I4;

/// Lanes in a float vector type.
template <class F>
constexpr int kLanes = static_cast<int>(sizeof(F) / sizeof(float));

template <class F = F4>
[[gnu::always_inline]] inline F splat(float s) {
  return F{} + s;
}
template <class F>
[[gnu::always_inline]] inline F vsqrt(F a) {
  if constexpr (kLanes<F> == 4)
    return reinterpret_cast<F>(_mm_sqrt_ps(reinterpret_cast<__m128>(a)));
  else if constexpr (kLanes<F> == 8)
    return reinterpret_cast<F>(_mm256_sqrt_ps(reinterpret_cast<__m256>(a)));
  else
    return reinterpret_cast<F>(_mm512_sqrt_ps(reinterpret_cast<__m512>(a)));
}
/// std::max(a, b) lane by lane (a where b < a is false, so a NaN a stays).
template <class F>
[[gnu::always_inline]] inline F vmax(F a, F b) {
  return a < b ? b : a;
}
/// Whether any lane of a comparison result is set.
template <class I>
[[gnu::always_inline]] inline bool any(I m) {
  if constexpr (sizeof(I) == 16)
    return _mm_movemask_ps(reinterpret_cast<__m128>(m)) != 0;
  else if constexpr (sizeof(I) == 32)
    return _mm256_movemask_ps(reinterpret_cast<__m256>(m)) != 0;
  else
    return _mm512_test_epi32_mask(reinterpret_cast<__m512i>(m), reinterpret_cast<__m512i>(m)) != 0;
}

/// a b + c for four lanes, rounded once (a fused multiply-add): the FMA instruction where
/// the translation unit has it (the AVX2 and AVX-512 kernels), else in double: the product
/// of two floats is exact there, the sum's rounding error is found exactly (Knuth's
/// TwoSum) and the sum rounded to odd instead (its last bit set where it was inexact), so
/// that rounding it to float gives the correctly rounded a b + c (round-to-odd at 53 >=
/// 2 x 24 + 2 bits; Boldo and Melquiond 2008): the same bits as the instruction, for
/// every finite result, overflow and zero sign included. SSE2 only.
[[gnu::always_inline]] inline __m128 madd4(__m128 a, __m128 b, __m128 c) {
#ifdef __FMA__
  return _mm_fmadd_ps(a, b, c);
#else
  const auto odd = [](__m128d x, __m128d y, __m128d z) {
    const __m128d p = _mm_mul_pd(x, y);  // exact: 48 bits at most
    const __m128d s = _mm_add_pd(p, z);
    const __m128d bb = _mm_sub_pd(s, p);
    const __m128d err = _mm_add_pd(_mm_sub_pd(p, _mm_sub_pd(s, bb)), _mm_sub_pd(z, bb));
    const __m128d zero = _mm_setzero_pd();
    // Inexact (err is 0 where exact, NaN where s is not finite: neither moves s).
    const __m128i inexact =
        _mm_castpd_si128(_mm_or_pd(_mm_cmplt_pd(err, zero), _mm_cmpgt_pd(err, zero)));
    const __m128i si = _mm_castpd_si128(s);
    // Last bit clear (the low 32-bit word of each lane tested, spread over the lane).
    const __m128i even = _mm_shuffle_epi32(
        _mm_cmpeq_epi32(_mm_and_si128(si, _mm_set1_epi32(1)), _mm_setzero_si128()),
        _MM_SHUFFLE(2, 2, 0, 0));
    // One unit in the last place toward the error: -1 where their signs differ, else +1.
    const __m128i differ = _mm_shuffle_epi32(
        _mm_srai_epi32(_mm_xor_si128(si, _mm_castpd_si128(err)), 31), _MM_SHUFFLE(3, 3, 1, 1));
    const __m128i step = _mm_or_si128(_mm_slli_epi64(differ, 1), _mm_set_epi32(0, 1, 0, 1));
    return _mm_castsi128_pd(_mm_add_epi64(si, _mm_and_si128(step, _mm_and_si128(inexact, even))));
  };
  const __m128d lo = odd(_mm_cvtps_pd(a), _mm_cvtps_pd(b), _mm_cvtps_pd(c));
  const __m128d hi = odd(_mm_cvtps_pd(_mm_movehl_ps(a, a)), _mm_cvtps_pd(_mm_movehl_ps(b, b)),
                         _mm_cvtps_pd(_mm_movehl_ps(c, c)));
  return _mm_movelh_ps(_mm_cvtpd_ps(lo), _mm_cvtpd_ps(hi));
#endif
}

/// a b + c lane by lane, rounded once (madd4; FMA instructions at 8 and 16 lanes).
template <class F>
[[gnu::always_inline]] inline F madd(F a, F b, F c) {
  if constexpr (kLanes<F> == 4)
    return reinterpret_cast<F>(madd4(reinterpret_cast<__m128>(a), reinterpret_cast<__m128>(b),
                                     reinterpret_cast<__m128>(c)));
  else if constexpr (kLanes<F> == 8)
    return reinterpret_cast<F>(_mm256_fmadd_ps(
        reinterpret_cast<__m256>(a), reinterpret_cast<__m256>(b), reinterpret_cast<__m256>(c)));
  else
    return reinterpret_cast<F>(_mm512_fmadd_ps(
        reinterpret_cast<__m512>(a), reinterpret_cast<__m512>(b), reinterpret_cast<__m512>(c)));
}

template <class F>
inline F vlog(F x) {
  using I = decltype(x < x);
  const I bits = reinterpret_cast<I>(x);
  I e = ((bits >> 23) & 0xff) - 127;
  F m = reinterpret_cast<F>((bits & 0x007fffff) | 0x3f800000);  // [1, 2)
  const I big = m > splat<F>(1.41421356f);
  m = big ? m * splat<F>(0.5f) : m;
  e = e - big;  // big is -1 where true
  const F f = m - splat<F>(1.0f);
  const F ef = __builtin_convertvector(e, F);
  const F z = f * f;
  F y = splat<F>(7.0376836292e-2f);
  y = madd(y, f, splat<F>(-1.1514610310e-1f));
  y = madd(y, f, splat<F>(1.1676998740e-1f));
  y = madd(y, f, splat<F>(-1.2420140846e-1f));
  y = madd(y, f, splat<F>(1.4249322787e-1f));
  y = madd(y, f, splat<F>(-1.6668057665e-1f));
  y = madd(y, f, splat<F>(2.0000714765e-1f));
  y = madd(y, f, splat<F>(-2.4999993993e-1f));
  y = madd(y, f, splat<F>(3.3333331174e-1f));
  y = y * f * z;
  y = madd(splat<F>(-2.12194440e-4f), ef, y);
  y = madd(splat<F>(-0.5f), z, y);
  F r = f + y;
  r = madd(splat<F>(0.693359375f), ef, r);
  const float inf = std::numeric_limits<float>::infinity();
  const F nan = splat<F>(std::numeric_limits<float>::quiet_NaN());
  r = x > splat<F>(0.0f) ? r : (x == splat<F>(0.0f) ? splat<F>(-inf) : nan);
  return x == splat<F>(inf) ? splat<F>(inf) : r;
}

/// A 3-vector of lanes.
template <class F>
struct V3 {
  F x, y, z;
};
template <class F>
[[gnu::always_inline]] inline V3<F> operator+(const V3<F>& a, const V3<F>& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class F>
[[gnu::always_inline]] inline V3<F> operator-(const V3<F>& a, const V3<F>& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class F>
[[gnu::always_inline]] inline V3<F> operator*(F s, const V3<F>& a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <class F>
[[gnu::always_inline]] inline F dot(const V3<F>& a, const V3<F>& b) {
  return madd(a.z, b.z, madd(a.y, b.y, a.x * b.x));
}
template <class F>
[[gnu::always_inline]] inline V3<F> cross(const V3<F>& a, const V3<F>& b) {
  return {madd(a.y, b.z, -(a.z * b.y)), madd(a.z, b.x, -(a.x * b.z)), madd(a.x, b.y, -(a.y * b.x))};
}

/// s a + c, each component rounded once (madd).
template <class F>
[[gnu::always_inline]] inline V3<F> madd(F s, const V3<F>& a, const V3<F>& c) {
  return {madd(s, a.x, c.x), madd(s, a.y, c.y), madd(s, a.z, c.z)};
}

/// Four SSE registers of one group of four lanes each as one W-lane vector (W = 4 n).
template <class F>
[[gnu::always_inline]] inline F join(const __m128* p) {
  if constexpr (kLanes<F> == 4) {
    return reinterpret_cast<F>(p[0]);
  } else if constexpr (kLanes<F> == 8) {
    return reinterpret_cast<F>(_mm256_insertf128_ps(_mm256_castps128_ps256(p[0]), p[1], 1));
  } else {
    const __m256 lo = _mm256_insertf128_ps(_mm256_castps128_ps256(p[0]), p[1], 1);
    const __m256 hi = _mm256_insertf128_ps(_mm256_castps128_ps256(p[2]), p[3], 1);
    return reinterpret_cast<F>(_mm512_insertf32x8(_mm512_castps256_ps512(lo), hi, 1));
  }
}
/// Lanes 4 g .. 4 g + 3 of v.
template <class F>
[[gnu::always_inline]] inline __m128 part(F v, int g) {
  if constexpr (kLanes<F> == 4) {
    return reinterpret_cast<__m128>(v);
  } else if constexpr (kLanes<F> == 8) {
    const __m256 r = reinterpret_cast<__m256>(v);
    return g == 0 ? _mm256_castps256_ps128(r) : _mm256_extractf128_ps(r, 1);
  } else {
    const __m512 r = reinterpret_cast<__m512>(v);
    switch (g) {
      case 0:
        return _mm512_castps512_ps128(r);
      case 1:
        return _mm512_extractf32x4_ps(r, 1);
      case 2:
        return _mm512_extractf32x4_ps(r, 2);
      default:
        return _mm512_extractf32x4_ps(r, 3);
    }
  }
}

}  // namespace shellmpm::kl::lanes

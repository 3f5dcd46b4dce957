// Four-lane float arithmetic for the batched Kirchhoff-Love force kernel
// (sim/shell/kl_batch.cpp): one SSE register of four quadrature points, element-wise
// operators (GCC vector extensions), a select, square root, and a vectorised natural
// logarithm. Internal to sim/shell.
//
// log4: x = m 2^e with m in [sqrt(1/2), sqrt(2)), log x = e log 2 + log m, log(1 + f) by the
// degree-9 minimax polynomial of Cephes' logf (Moshier) and log 2 split in two parts
// (0.693359375 exact in float, plus -2.12194440e-4): within 2 ulp of std::log on normal
// numbers (tests/sim/shell/test_kl_batch.cpp). Zero gives -inf, negatives and NaN give
// NaN, inf gives inf, as std::log; subnormals are read as their normal neighbours' scale
// (a layer that thin has blown up long before).
#pragma once
#include <immintrin.h>

#include <cstdint>
#include <limits>

namespace shellmpm::kl::lanes {

typedef float F4 __attribute__((vector_size(16)));
typedef std::int32_t I4 __attribute__((vector_size(16)));

[[gnu::always_inline]] inline F4 splat(float s) {
  return F4{s, s, s, s};
}
[[gnu::always_inline]] inline F4 sqrt4(F4 a) {
  return reinterpret_cast<F4>(_mm_sqrt_ps(reinterpret_cast<__m128>(a)));
}
/// std::max(a, b) lane by lane (a where b < a is false, so a NaN a stays).
[[gnu::always_inline]] inline F4 max4(F4 a, F4 b) {
  return a < b ? b : a;
}

inline F4 log4(F4 x) {
  const I4 bits = reinterpret_cast<I4>(x);
  I4 e = ((bits >> 23) & 0xff) - 127;
  F4 m = reinterpret_cast<F4>((bits & 0x007fffff) | 0x3f800000);  // [1, 2)
  const I4 big = m > splat(1.41421356f);
  m = big ? m * splat(0.5f) : m;
  e = e - big;  // big is -1 where true
  const F4 f = m - splat(1.0f);
  const F4 ef = __builtin_convertvector(e, F4);
  const F4 z = f * f;
  F4 y = splat(7.0376836292e-2f);
  y = y * f - splat(1.1514610310e-1f);
  y = y * f + splat(1.1676998740e-1f);
  y = y * f - splat(1.2420140846e-1f);
  y = y * f + splat(1.4249322787e-1f);
  y = y * f - splat(1.6668057665e-1f);
  y = y * f + splat(2.0000714765e-1f);
  y = y * f - splat(2.4999993993e-1f);
  y = y * f + splat(3.3333331174e-1f);
  y = y * f * z;
  y = y + splat(-2.12194440e-4f) * ef;
  y = y - splat(0.5f) * z;
  F4 r = f + y;
  r = r + splat(0.693359375f) * ef;
  const float inf = std::numeric_limits<float>::infinity();
  const F4 nan = splat(std::numeric_limits<float>::quiet_NaN());
  r = x > splat(0.0f) ? r : (x == splat(0.0f) ? splat(-inf) : nan);
  return x == splat(inf) ? splat(inf) : r;
}

/// A 3-vector of lanes.
struct V3 {
  F4 x, y, z;
};
[[gnu::always_inline]] inline V3 operator+(const V3& a, const V3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
[[gnu::always_inline]] inline V3 operator-(const V3& a, const V3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
[[gnu::always_inline]] inline V3 operator*(F4 s, const V3& a) {
  return {s * a.x, s * a.y, s * a.z};
}
[[gnu::always_inline]] inline F4 dot(const V3& a, const V3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
[[gnu::always_inline]] inline V3 cross(const V3& a, const V3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

}  // namespace shellmpm::kl::lanes

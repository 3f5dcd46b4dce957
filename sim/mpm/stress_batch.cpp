#include "sim/mpm/stress_batch.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "sim/mpm/constitutive.h"

namespace shellmpm {
namespace {

SimdLevel detect() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl"))
    return SimdLevel::Avx512;
  // (Every CPU with AVX2 has FMA as well; the Kirchhoff-Love kernel's AVX2 instance uses it.)
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return SimdLevel::Avx2;
  return SimdLevel::Sse;
}

SimdLevel from_environment(SimdLevel best) {
  const char* e = std::getenv("SHELLMPM_SIMD");
  if (!e) return best;
  SimdLevel want = best;
  if (std::strcmp(e, "sse") == 0)
    want = SimdLevel::Sse;
  else if (std::strcmp(e, "avx2") == 0)
    want = SimdLevel::Avx2;
  else if (std::strcmp(e, "avx512") == 0)
    want = SimdLevel::Avx512;
  else
    std::fprintf(stderr, "shellmpm: SHELLMPM_SIMD='%s' is not one of sse, avx2, avx512; using %s\n",
                 e, simd_name(best));
  return static_cast<int>(want) < static_cast<int>(best) ? want : best;
}

std::atomic<int>& level_slot() {
  static std::atomic<int> slot(static_cast<int>(from_environment(simd_supported())));
  return slot;
}

bool dispatch(int op, const ConstitutiveModelT<Real>& m, Mat3* F, const Real* plastic_in,
              Real* plastic, Mat3* tau, std::size_t n) {
  const auto level = static_cast<SimdLevel>(level_slot().load(std::memory_order_relaxed));
  if (level == SimdLevel::Avx512)
    stress_batch::run_avx512(op, m, F, plastic_in, plastic, tau, n);
  else if (level == SimdLevel::Avx2)
    stress_batch::run_avx2(op, m, F, plastic_in, plastic, tau, n);
  else
    return false;
  return true;
}

}  // namespace

SimdLevel simd_supported() {
  static const SimdLevel best = detect();
  return best;
}

SimdLevel simd_level() {
  return static_cast<SimdLevel>(level_slot().load(std::memory_order_relaxed));
}

void set_simd_level(SimdLevel level) {
  const SimdLevel best = simd_supported();
  level_slot().store(static_cast<int>(level) < static_cast<int>(best) ? static_cast<int>(level)
                                                                      : static_cast<int>(best));
}

const char* simd_name(SimdLevel level) {
  switch (level) {
    case SimdLevel::Avx512:
      return "avx512";
    case SimdLevel::Avx2:
      return "avx2";
    default:
      return "sse";
  }
}

namespace stress_batch {

bool kirchhoff(const ConstitutiveModelT<Real>& m, const Mat3* F, const Real* plastic, Mat3* tau,
               std::size_t n) {
  return dispatch(0, m, const_cast<Mat3*>(F), plastic, nullptr, tau, n);
}

bool project(const ConstitutiveModelT<Real>& m, Mat3* F, Real* plastic, std::size_t n) {
  return dispatch(1, m, F, nullptr, plastic, nullptr, n);
}

bool project_and_kirchhoff(const ConstitutiveModelT<Real>& m, Mat3* F, Real* plastic, Mat3* tau,
                           std::size_t n) {
  return dispatch(2, m, F, nullptr, plastic, tau, n);
}

}  // namespace stress_batch
}  // namespace shellmpm

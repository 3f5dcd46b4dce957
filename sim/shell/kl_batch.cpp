// KirchhoffLoveShellT<float>::eval_points: the batched kernel (sim/shell/kl_batch_body.h)
// on the widest instruction set simd_level() allows (AVX-512: 16 points per register,
// AVX2: 8, SSE: 4; the same bits on each), over chunks of points whose energies it then
// adds in point order. This file is the SSE instance; kl_batch_avx2.cpp and
// kl_batch_avx512.cpp compile the others.
#define SHELLMPM_KL_BATCH_ENTRY eval_batch_sse
#define SHELLMPM_KL_PATCH_ENTRY eval_patches_sse
#define SHELLMPM_KL_BATCH_WIDTH 4
#include "sim/shell/kl_batch_body.h"

#include "sim/mpm/stress_batch.h"
#include "sim/shell/kirchhoff_love.h"

namespace shellmpm {

template <>
kl::BatchData KirchhoffLoveShellT<float>::batch_data() const {
  return kl::BatchData{begin_.data(),
                       ctrl_.data(),
                       coef_.data(),
                       slot_.data(),
                       area_.data(),
                       B_.data(),
                       fp_inv_.empty() ? nullptr : fp_inv_.data(),
                       layer_xi3_.data(),
                       layer_w_.data(),
                       num_layers_,
                       mu_,
                       lambda_,
                       stiffening_.limit,
                       stiffening_.log_limit,
                       stiffening_.k};
}

template <>
void KirchhoffLoveShellT<float>::eval_points(std::size_t q0, std::size_t n, const Vec3T* x,
                                             float* fe, double& e_total, double* e_membrane) const {
  static_assert(sizeof(Vec3T) == 3 * sizeof(float), "control points as packed floats");
  const kl::BatchData d = batch_data();
  const SimdLevel level = simd_level();
  const kl::BatchFn run = level == SimdLevel::Avx512 ? kl::eval_batch_avx512
                          : level == SimdLevel::Avx2 ? kl::eval_batch_avx2
                                                     : kl::eval_batch_sse;
  // A multiple of every width, so that no chunk splits a register's points differently.
  constexpr std::size_t kChunk = 64;
  float energy[kChunk];
  float a12[6 * kChunk];
  const float* xs = x ? x->data() : nullptr;
  for (std::size_t b = q0; b < q0 + n; b += kChunk) {
    const std::size_t m = std::min(kChunk, q0 + n - b);
    run(d, b, m, xs, fe, energy, e_membrane ? a12 : nullptr);
    for (std::size_t i = 0; i < m; ++i) {
      e_total += double(energy[i]);
      if (e_membrane)
        *e_membrane += membrane_energy(b + i, Vec3T(a12[6 * i], a12[6 * i + 1], a12[6 * i + 2]),
                                       Vec3T(a12[6 * i + 3], a12[6 * i + 4], a12[6 * i + 5]));
    }
  }
}

template <>
void KirchhoffLoveShellT<float>::eval_patch_range(std::size_t i0, std::size_t n, const Vec3T* x,
                                                  float* fe, double* e_total,
                                                  double* e_membrane) const {
  const kl::BatchData d = batch_data();
  const kl::Patches& pt = patches_;
  const kl::PatchData p{
      pt.points,       pt.order.data(),   pt.pattern.data(),      pt.begin.data(),
      pt.ctrl.data(),  pt.slot.data(),    pt.pattern_size.data(), pt.pattern_coef.data(),
      pt.coefs.data(), pt.B_lanes.data(), pt.area_lanes.data()};
  const SimdLevel level = simd_level();
  const kl::PatchFn run = level == SimdLevel::Avx512 ? kl::eval_patches_avx512
                          : level == SimdLevel::Avx2 ? kl::eval_patches_avx2
                                                     : kl::eval_patches_sse;
  // Chunks of a multiple of every width (the batches break at pattern changes anyway).
  constexpr std::size_t kChunk = 16;
  const std::size_t P = std::size_t(pt.points);
  float energy[kChunk * kl::Patches::kMaxPoints];
  float a12[6 * kChunk * kl::Patches::kMaxPoints];
  const float* xs = x ? x->data() : nullptr;
  for (std::size_t b = i0; b < i0 + n; b += kChunk) {
    const std::size_t m = std::min(kChunk, i0 + n - b);
    run(d, p, b, m, xs, fe, energy, e_membrane ? a12 : nullptr);
    if (!e_total) continue;
    for (std::size_t i = 0; i < m; ++i)
      for (std::size_t k = 0; k < P; ++k) {
        const std::size_t o = i * P + k;
        *e_total += double(energy[o]);
        if (e_membrane) {
          const std::size_t q = std::size_t(pt.order[b + i]) * P + k;
          *e_membrane += membrane_energy(q, Vec3T(a12[6 * o], a12[6 * o + 1], a12[6 * o + 2]),
                                         Vec3T(a12[6 * o + 3], a12[6 * o + 4], a12[6 * o + 5]));
        }
      }
  }
}

}  // namespace shellmpm

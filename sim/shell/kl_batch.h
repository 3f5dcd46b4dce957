// The batched float Kirchhoff-Love kernel (sim/shell/kl_batch_body.h) and its entry points
// per instruction set: KirchhoffLoveShellT<float>::eval_points (sim/shell/kl_batch.cpp)
// picks one by simd_level() (sim/mpm/stress_batch.h). Internal to sim/shell.
#pragma once
#include <cstddef>
#include <cstdint>

#include "sim/shell/kl_patches.h"

namespace shellmpm::kl {

/// A shell's per-point and per-entry arrays as the kernel reads them
/// (KirchhoffLoveShellT's members of the same names).
struct BatchData {
  const std::size_t* begin;   ///< entries of point q: [begin[q], begin[q + 1])
  const int* ctrl;            ///< control point of each entry
  const float* coef;          ///< 5 per entry: N1, N2, N11, N12, N22
  const std::uint32_t* slot;  ///< gather-order slot of each entry
  const float* area;          ///< per point
  const float* B;             ///< 4 per (point, layer)
  const float* fp_inv;        ///< 4 per (point, layer), or null without plasticity
  const float* layer_xi3;     ///< per layer
  const float* layer_w;       ///< per layer
  int num_layers;
  float mu, lambda;
  float limit, log_limit, k;  ///< the large-stretch term
};

/// Points q0 .. q0 + n - 1: energy[i] the energy of point q0 + i; where fe is not null,
/// each entry's force share (x, y, z, 0) at fe[4 slot[e]]; where a12 is not null,
/// a_1 and a_2 of point q0 + i at a12[6 i]. x: 3 floats per control point.
using BatchFn = void (*)(const BatchData& d, std::size_t q0, std::size_t n, const float* x,
                         float* fe, float* energy, float* a12);
void eval_batch_sse(const BatchData& d, std::size_t q0, std::size_t n, const float* x, float* fe,
                    float* energy, float* a12);
void eval_batch_avx2(const BatchData& d, std::size_t q0, std::size_t n, const float* x, float* fe,
                     float* energy, float* a12);
void eval_batch_avx512(const BatchData& d, std::size_t q0, std::size_t n, const float* x, float* fe,
                       float* energy, float* a12);

/// A shell's patches (kl_patches.h) as the patch kernel reads them.
struct PatchData {
  int points;
  const std::uint32_t* order;
  const std::uint32_t* pattern;
  const std::uint32_t* begin;
  const int* ctrl;
  const std::uint32_t* slot;
  const std::uint32_t* pattern_size;
  const std::uint32_t* pattern_coef;
  const float* coefs;
  const float* B_lanes;     ///< Patches::B_lanes
  const float* area_lanes;  ///< Patches::area_lanes
};

/// Patches p.order[i0 .. i0 + n - 1]: energy[(i - i0) P + k] the energy of point k of the
/// patch at position i; where fe is not null, each patch entry's force share (x, y, z, 0) at
/// fe[4 slot[e]]; where a12 is not null, that point's a_1 and a_2 at a12[6 ((i - i0) P + k)].
using PatchFn = void (*)(const BatchData& d, const PatchData& p, std::size_t i0, std::size_t n,
                         const float* x, float* fe, float* energy, float* a12);
void eval_patches_sse(const BatchData& d, const PatchData& p, std::size_t i0, std::size_t n,
                      const float* x, float* fe, float* energy, float* a12);
void eval_patches_avx2(const BatchData& d, const PatchData& p, std::size_t i0, std::size_t n,
                       const float* x, float* fe, float* energy, float* a12);
void eval_patches_avx512(const BatchData& d, const PatchData& p, std::size_t i0, std::size_t n,
                         const float* x, float* fe, float* energy, float* a12);

}  // namespace shellmpm::kl

// The batched float Kirchhoff-Love kernel (sim/shell/kl_batch_body.h) and its entry points
// per instruction set: KirchhoffLoveShellT<float>::eval_points (sim/shell/kl_batch.cpp)
// picks one by simd_level() (sim/mpm/stress_batch.h). Internal to sim/shell.
#pragma once
#include <cstddef>
#include <cstdint>

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

}  // namespace shellmpm::kl

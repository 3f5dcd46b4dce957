// The per-particle loops of the bulk transfers (sim/mpm/transfer.cpp) for one particle
// block: the P2G scatter (with the block's Kirchhoff stresses already computed) and the
// G2P gather with the particle update. The library compiles them for x86-64-v2 (SSE);
// transfer_blocks_avx2.cpp and transfer_blocks_avx512.cpp compile the same templates for
// wider units, with no contraction into fused multiply-adds, and transfer.cpp picks one
// at run time (simd_level(), sim/mpm/stress_batch.h). Every instruction set gives the same
// bits (tests/sim/mpm/test_stress_batch.cpp).
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstring>

#include "sim/mpm/apic_stencil.h"
#include "sim/mpm/transfer.h"

namespace shellmpm::transfer_blocks {

/// First position in block b's slice of grid.order that holds a bulk particle (indices
/// ascend within a block, other points come first).
inline std::uint32_t bulk_begin(const SparseGrid& grid, const TransferParams& tp, std::size_t b) {
  const std::uint32_t s0 = grid.pblock_start[b], s1 = grid.pblock_start[b + 1];
  if (tp.first_bulk == 0) return s0;
  const auto* o = grid.order.data();
  return static_cast<std::uint32_t>(std::lower_bound(o + s0, o + s1, tp.first_bulk) - o);
}

/// Zeroes block b's buffer and scatters its bulk particles; tau[i] is the Kirchhoff stress
/// of the block's i-th bulk particle.
template <bool kMls>
inline void p2g(const ParticleSet& p, SparseGrid& grid, const TransferParams& tp, std::size_t b,
                const Mat3* tau) {
  auto& buf = grid.pblock_buf[b];
  std::memset(static_cast<void*>(buf.data()), 0, sizeof(buf));
  const Vec3i bc = unpack_block(grid.pblock_key[b]) * kBlockSize;
  const Real dx = static_cast<Real>(grid.dx());
  const Real dt = tp.dt;
  const auto& rho = *tp.densities;
  const std::uint32_t s0 = bulk_begin(grid, tp, b);
  for (std::uint32_t s = s0; s < grid.pblock_start[b + 1]; ++s) {
    const std::uint32_t q = grid.order[s] - tp.first_bulk;
    const QuadraticWeights W(grid.grid_coord(p.x[q]));
    const Real vol = p.volume[q];
    const Real m = vol * rho[p.material[q]];
    // Affine term in grid units: world dpos = dx * (node - fx).
    Mat3 A = (m * dx) * p.C[q];
    Mat3 S = Mat3::Zero();
    if (kMls)
      A -= (Real(4) * dt * vol / dx) * tau[s - s0];  // MLS: -dt V0 M^-1 tau, M^-1 = 4/dx^2
    else
      S = (dt * vol / dx) * tau[s - s0];  // APIC: -dt V0 tau grad w, grad w = dw_grid / dx
    const Vec3 fx(W.fx[0], W.fx[1], W.fx[2]);
    apic_scatter<!kMls>(buf.data(), W, bc, m, m * p.v[q] - A * fx, A, S);
  }
}

/// Gathers block b's bulk particles: v, C, x += dt v, F = (I + dt grad v) F.
template <bool kMls>
inline void g2p(ParticleSet& p, const SparseGrid& grid, const TransferParams& tp, std::size_t b) {
  const auto& buf = grid.pblock_buf[b];
  const Vec3i bc = unpack_block(grid.pblock_key[b]) * kBlockSize;
  const Real dx = static_cast<Real>(grid.dx());
  const Real inv_dx = Real(1) / dx;
  const Real dt = tp.dt;
  for (std::uint32_t s = bulk_begin(grid, tp, b); s < grid.pblock_start[b + 1]; ++s) {
    const std::uint32_t q = grid.order[s] - tp.first_bulk;
    const QuadraticWeights W(grid.grid_coord(p.x[q]));
    const ApicGather G = apic_gather<!kMls>(buf.data(), W, bc);
    // C = B D^-1 with D = dx^2/4 I, B_world = dx B.
    const Mat3 C = (Real(4) * inv_dx) * G.B;
    const Mat3 gradv = kMls ? C : Mat3(inv_dx * G.grad);
    const Vec3& v = G.v;
    p.v[q] = v;
    p.C[q] = C;
    p.x[q] += dt * v;
    p.F[q] = (Mat3::Identity() + dt * gradv) * p.F[q];
  }
}

/// The per-ISA entry points: p2g<mls> and g2p<mls> compiled for AVX2 (-mavx2, no FMA) and
/// AVX-512 (-march=x86-64-v4), flattened so that their objects define nothing else.
void p2g_avx2(bool mls, const ParticleSet& p, SparseGrid& grid, const TransferParams& tp,
              std::size_t b, const Mat3* tau);
void g2p_avx2(bool mls, ParticleSet& p, const SparseGrid& grid, const TransferParams& tp,
              std::size_t b);
void p2g_avx512(bool mls, const ParticleSet& p, SparseGrid& grid, const TransferParams& tp,
                std::size_t b, const Mat3* tau);
void g2p_avx512(bool mls, ParticleSet& p, const SparseGrid& grid, const TransferParams& tp,
                std::size_t b);

}  // namespace shellmpm::transfer_blocks

/// Defines the entry points p2g_<isa> and g2p_<isa> in the including translation unit.
#define SHELLMPM_TRANSFER_BLOCKS_ENTRIES(isa)                                               \
  namespace shellmpm::transfer_blocks {                                                     \
  __attribute__((flatten)) void p2g_##isa(bool mls, const ParticleSet& p, SparseGrid& grid, \
                                          const TransferParams& tp, std::size_t b,          \
                                          const Mat3* tau) {                                \
    if (mls)                                                                                \
      p2g<true>(p, grid, tp, b, tau);                                                       \
    else                                                                                    \
      p2g<false>(p, grid, tp, b, tau);                                                      \
  }                                                                                         \
  __attribute__((flatten)) void g2p_##isa(bool mls, ParticleSet& p, const SparseGrid& grid, \
                                          const TransferParams& tp, std::size_t b) {        \
    if (mls)                                                                                \
      g2p<true>(p, grid, tp, b);                                                            \
    else                                                                                    \
      g2p<false>(p, grid, tp, b);                                                           \
  }                                                                                         \
  }

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

/// Calls f(q, i) for block b's bulk particles in ascending order (other points, indices
/// below tp.first_bulk, are skipped): q the particle's index in the set, i its place among
/// the block's bulk particles.
template <class F>
inline void for_each_bulk(const SparseGrid& grid, const TransferParams& tp, std::size_t b, F&& f) {
  std::uint32_t i = 0;
  grid.for_each_point(
      b, [&](std::uint32_t g) { f(g - tp.first_bulk, i++); }, tp.first_bulk);
}

/// Zeroes buf (block b's padded buffer, kPadNodes nodes) and scatters the block's bulk
/// particles into it; tau[i] is the Kirchhoff stress of the block's i-th bulk particle.
template <bool kMls>
inline void p2g(const ParticleSet& p, const SparseGrid& grid, const TransferParams& tp,
                std::size_t b, const Mat3* tau, GridNode* buf) {
  std::memset(static_cast<void*>(buf), 0, kPadNodes * sizeof(GridNode));
  const Vec3i bc = unpack_block(grid.pblock_key[b]) * kBlockSize;
  const Real dx = static_cast<Real>(grid.dx());
  const Real dt = tp.dt;
  const auto& rho = *tp.densities;
  for_each_bulk(grid, tp, b, [&](std::uint32_t q, std::uint32_t i) {
    const QuadraticWeights W(grid.grid_coord(p.x[q]));
    const Real vol = p.volume_of(q);
    const Real m = vol * rho[p.material_of(q)];
    // Affine term in grid units: world dpos = dx * (node - fx).
    Mat3 A = (m * dx) * p.C[q];
    Mat3 S = Mat3::Zero();
    if (kMls)
      A -= (Real(4) * dt * vol / dx) * tau[i];  // MLS: -dt V0 M^-1 tau, M^-1 = 4/dx^2
    else
      S = (dt * vol / dx) * tau[i];  // APIC: -dt V0 tau grad w, grad w = dw_grid / dx
    const Vec3 fx(W.fx[0], W.fx[1], W.fx[2]);
    apic_scatter<!kMls>(buf, W, bc, m, m * p.v[q] - A * fx, A, S);
  });
}

/// Gathers block b's bulk particles from buf (its padded buffer): v, C, x += dt v,
/// F = (I + dt grad v) F.
template <bool kMls>
inline void g2p(ParticleSet& p, const SparseGrid& grid, const TransferParams& tp, std::size_t b,
                const GridNode* buf) {
  const Vec3i bc = unpack_block(grid.pblock_key[b]) * kBlockSize;
  const Real dx = static_cast<Real>(grid.dx());
  const Real inv_dx = Real(1) / dx;
  const Real dt = tp.dt;
  for_each_bulk(grid, tp, b, [&](std::uint32_t q, std::uint32_t) {
    const QuadraticWeights W(grid.grid_coord(p.x[q]));
    const ApicGather G = apic_gather<!kMls>(buf, W, bc);
    // C = B D^-1 with D = dx^2/4 I, B_world = dx B.
    const Mat3 C = (Real(4) * inv_dx) * G.B;
    const Mat3 gradv = kMls ? C : Mat3(inv_dx * G.grad);
    const Vec3& v = G.v;
    p.v[q] = v;
    p.C[q] = C;
    p.x[q] += dt * v;
    p.F[q] = (Mat3::Identity() + dt * gradv) * p.F[q];
  });
}

/// The per-ISA entry points: p2g<mls> and g2p<mls> compiled for AVX2 (-mavx2, no FMA) and
/// AVX-512 (-march=x86-64-v4), flattened so that their objects define nothing else.
void p2g_avx2(bool mls, const ParticleSet& p, const SparseGrid& grid, const TransferParams& tp,
              std::size_t b, const Mat3* tau, GridNode* buf);
void g2p_avx2(bool mls, ParticleSet& p, const SparseGrid& grid, const TransferParams& tp,
              std::size_t b, const GridNode* buf);
void p2g_avx512(bool mls, const ParticleSet& p, const SparseGrid& grid, const TransferParams& tp,
                std::size_t b, const Mat3* tau, GridNode* buf);
void g2p_avx512(bool mls, ParticleSet& p, const SparseGrid& grid, const TransferParams& tp,
                std::size_t b, const GridNode* buf);

}  // namespace shellmpm::transfer_blocks

/// Defines the entry points p2g_<isa> and g2p_<isa> in the including translation unit.
#define SHELLMPM_TRANSFER_BLOCKS_ENTRIES(isa)                                                     \
  namespace shellmpm::transfer_blocks {                                                           \
  __attribute__((flatten)) void p2g_##isa(bool mls, const ParticleSet& p, const SparseGrid& grid, \
                                          const TransferParams& tp, std::size_t b,                \
                                          const Mat3* tau, GridNode* buf) {                       \
    if (mls)                                                                                      \
      p2g<true>(p, grid, tp, b, tau, buf);                                                        \
    else                                                                                          \
      p2g<false>(p, grid, tp, b, tau, buf);                                                       \
  }                                                                                               \
  __attribute__((flatten)) void g2p_##isa(bool mls, ParticleSet& p, const SparseGrid& grid,       \
                                          const TransferParams& tp, std::size_t b,                \
                                          const GridNode* buf) {                                  \
    if (mls)                                                                                      \
      g2p<true>(p, grid, tp, b, buf);                                                             \
    else                                                                                          \
      g2p<false>(p, grid, tp, b, buf);                                                            \
  }                                                                                               \
  }

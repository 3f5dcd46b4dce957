#include "sim/mpm/transfer.h"

#include <algorithm>
#include <cstring>
#include <type_traits>

#include "sim/core/parallel.h"
#include "sim/mpm/stress_batch.h"
#include "sim/mpm/transfer_blocks.h"

namespace shellmpm {
namespace {

using transfer_blocks::bulk_begin;

// Kirchhoff stresses of one particle block, in block order, computed in SIMD batches
// over runs of particles that share a material.
void block_stresses(const ParticleSet& p, const SparseGrid& grid, const TransferParams& tp,
                    std::size_t b, std::vector<Mat3>& F, std::vector<Real>& pl,
                    std::vector<Mat3>& tau) {
  const std::uint32_t s0 = bulk_begin(grid, tp, b), s1 = grid.pblock_start[b + 1];
  const std::size_t n = s1 - s0;
  const std::uint32_t off = tp.first_bulk;
  F.resize(n);
  pl.resize(n);
  tau.resize(n);
  const bool plastic = p.has_plastic();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t q = grid.order[s0 + i] - off;
    F[i] = p.F[q];
    pl[i] = plastic ? p.plastic[q] : Real(0);
  }
  if (!tp.stress) {
    std::fill(tau.begin(), tau.end(), Mat3::Zero());
    return;
  }
  std::size_t i = 0;
  while (i < n) {
    const auto mat = p.material[grid.order[s0 + i] - off];
    std::size_t j = i + 1;
    while (j < n && p.material[grid.order[s0 + j] - off] == mat) ++j;
    (*tp.models)[mat].kirchhoff_batch(F.data() + i, plastic ? pl.data() + i : nullptr,
                                      tau.data() + i, j - i);
    i = j;
  }
}

template <bool kMls>
void p2g_block(const ParticleSet& p, SparseGrid& grid, const TransferParams& tp, std::size_t b) {
  thread_local std::vector<Mat3> F_local, tau_local;
  thread_local std::vector<Real> pl_local;
  block_stresses(p, grid, tp, b, F_local, pl_local, tau_local);
  const SimdLevel level = simd_level();
  if (level == SimdLevel::Avx512)
    transfer_blocks::p2g_avx512(kMls, p, grid, tp, b, tau_local.data());
  else if (level == SimdLevel::Avx2)
    transfer_blocks::p2g_avx2(kMls, p, grid, tp, b, tau_local.data());
  else
    transfer_blocks::p2g<kMls>(p, grid, tp, b, tau_local.data());
}

template <bool kMls>
void g2p_block(ParticleSet& p, SparseGrid& grid, const TransferParams& tp, std::size_t b) {
  const SimdLevel level = simd_level();
  if (level == SimdLevel::Avx512)
    transfer_blocks::g2p_avx512(kMls, p, grid, tp, b);
  else if (level == SimdLevel::Avx2)
    transfer_blocks::g2p_avx2(kMls, p, grid, tp, b);
  else
    transfer_blocks::g2p<kMls>(p, grid, tp, b);
}

/// For every particle block b in parallel: block(b, kMls) with the scheme's flag (APIC or
/// MLS), then tp.others on the block's buffer.
template <class Block>
void each_particle_block(SparseGrid& grid, const TransferParams& tp, Block&& block) {
  parallel_for_each(
      grid.num_particle_blocks(), 1,
      [&](std::size_t b) {
        if (tp.mls)
          block(b, std::true_type());
        else
          block(b, std::false_type());
        if (tp.others) tp.others(b, grid.pblock_buf[b].data());
      },
      tp.serial);
}

}  // namespace

void particles_to_grid(const ParticleSet& p, SparseGrid& grid, const TransferParams& tp) {
  each_particle_block(
      grid, tp, [&](std::size_t b, auto mls) { p2g_block<decltype(mls)::value>(p, grid, tp, b); });
  grid.gather_buffers_to_grid(tp.serial);
}

void grid_to_particles(ParticleSet& p, SparseGrid& grid, const TransferParams& tp) {
  grid.scatter_grid_to_buffers(tp.serial);
  each_particle_block(
      grid, tp, [&](std::size_t b, auto mls) { g2p_block<decltype(mls)::value>(p, grid, tp, b); });
}

}  // namespace shellmpm

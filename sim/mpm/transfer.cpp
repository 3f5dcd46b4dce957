#include "sim/mpm/transfer.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <type_traits>

#include "sim/core/parallel.h"
#include "sim/mpm/stress_batch.h"
#include "sim/mpm/transfer_blocks.h"

namespace shellmpm {
namespace {

using transfer_blocks::for_each_bulk;

// Kirchhoff stresses of one particle block, in block order, computed in SIMD batches
// over runs of particles that share a material.
void block_stresses(const ParticleSet& p, const SparseGrid& grid, const TransferParams& tp,
                    std::size_t b, std::vector<Mat3>& F, std::vector<Real>& pl,
                    std::vector<std::uint16_t>& mat_of, std::vector<Mat3>& tau) {
  F.clear();
  pl.clear();
  mat_of.clear();
  const bool plastic = p.has_plastic();
  for_each_bulk(grid, tp, b, [&](std::uint32_t q, std::uint32_t) {
    F.push_back(p.F[q]);
    pl.push_back(plastic ? p.plastic[q] : Real(0));
    mat_of.push_back(p.material_of(q));
  });
  const std::size_t n = F.size();
  tau.resize(n);
  if (!tp.stress) {
    std::fill(tau.begin(), tau.end(), Mat3::Zero());
    return;
  }
  std::size_t i = 0;
  while (i < n) {
    const auto mat = mat_of[i];
    std::size_t j = i + 1;
    while (j < n && mat_of[j] == mat) ++j;
    (*tp.models)[mat].kirchhoff_batch(F.data() + i, plastic ? pl.data() + i : nullptr,
                                      tau.data() + i, j - i);
    i = j;
  }
}

template <bool kMls>
void p2g_block(const ParticleSet& p, const SparseGrid& grid, const TransferParams& tp,
               std::size_t b, GridNode* buf) {
  thread_local std::vector<Mat3> F_local, tau_local;
  thread_local std::vector<Real> pl_local;
  thread_local std::vector<std::uint16_t> mat_local;
  block_stresses(p, grid, tp, b, F_local, pl_local, mat_local, tau_local);
  const SimdLevel level = simd_level();
  if (level == SimdLevel::Avx512)
    transfer_blocks::p2g_avx512(kMls, p, grid, tp, b, tau_local.data(), buf);
  else if (level == SimdLevel::Avx2)
    transfer_blocks::p2g_avx2(kMls, p, grid, tp, b, tau_local.data(), buf);
  else
    transfer_blocks::p2g<kMls>(p, grid, tp, b, tau_local.data(), buf);
}

template <bool kMls>
void g2p_block(ParticleSet& p, const SparseGrid& grid, const TransferParams& tp, std::size_t b,
               const GridNode* buf) {
  const SimdLevel level = simd_level();
  if (level == SimdLevel::Avx512)
    transfer_blocks::g2p_avx512(kMls, p, grid, tp, b, buf);
  else if (level == SimdLevel::Avx2)
    transfer_blocks::g2p_avx2(kMls, p, grid, tp, b, buf);
  else
    transfer_blocks::g2p<kMls>(p, grid, tp, b, buf);
}

/// block(b, buf, kMls) with the scheme's flag (APIC or MLS) as a type.
template <class Block>
void with_scheme(const TransferParams& tp, std::size_t b, GridNode* buf, Block&& block) {
  if (tp.mls)
    block(b, buf, std::true_type());
  else
    block(b, buf, std::false_type());
}

/// A thread's padded buffer for the bulk-only transfers (no buffer per block is kept).
GridNode* thread_pad() {
  alignas(64) thread_local std::array<GridNode, kPadNodes> pad;
  return pad.data();
}

/// A thread's padded buffer that is all 0 between uses (blocks without bulk particles).
GridNode* thread_clean_pad() {
  alignas(64) thread_local std::array<GridNode, kPadNodes> pad{};
  return pad.data();
}

/// Whether particle block b holds bulk particles (binned from first_bulk on: the last of
/// its ascending runs reaches there). Blocks of shell points alone skip the bulk work.
bool has_bulk(const SparseGrid& grid, const TransferParams& tp, std::size_t b) {
  const std::uint32_t r = grid.block_run_start[b + 1];
  if (r == grid.block_run_start[b]) return false;
  return grid.block_runs[r - 1][0] + grid.block_runs[r - 1][1] > tp.first_bulk;
}

}  // namespace

void particles_to_grid(const ParticleSet& p, SparseGrid& grid, const TransferParams& tp) {
  auto block = [&](std::size_t b, GridNode* buf, auto mls) {
    p2g_block<decltype(mls)::value>(p, grid, tp, b, buf);
  };
  // Colour by colour, each block (its bulk particles, then tp.others: the shells' points)
  // into a thread's padded buffer and from there straight into the grid.
  grid.for_each_block_by_colour(
      [&](std::size_t b) {
        if (!has_bulk(grid, tp, b)) {
          // Other points alone: the nodes they reached, in a buffer kept all 0 between uses.
          GridNode* pad = thread_clean_pad();
          PadBox box;
          if (tp.others) tp.others(b, pad, &box);
          grid.add_pad_to_grid(b, pad, box);
          SparseGrid::zero_pad_box(pad, box);
          return;
        }
        GridNode* pad = thread_pad();
        with_scheme(tp, b, pad, block);  // zeroes the buffer first
        if (tp.others) tp.others(b, pad, nullptr);
        grid.add_pad_to_grid(b, pad);
      },
      tp.serial);
  grid.zero_unset_blocks(tp.serial);  // every block is reached: a scan of one byte each
}

void grid_to_particles(ParticleSet& p, SparseGrid& grid, const TransferParams& tp) {
  auto block = [&](std::size_t b, GridNode* buf, auto mls) {
    g2p_block<decltype(mls)::value>(p, grid, tp, b, buf);
  };
  parallel_for_each(
      grid.num_particle_blocks(), 1,
      [&](std::size_t b) {
        GridNode* pad = thread_pad();
        grid.copy_grid_to_pad(b, pad);
        if (has_bulk(grid, tp, b)) with_scheme(tp, b, pad, block);
        if (tp.others) tp.others(b, pad, nullptr);
      },
      tp.serial);
}

}  // namespace shellmpm

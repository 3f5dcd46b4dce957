#include "sim/mpm/transfer.h"

#include <algorithm>
#include <cstring>
#include <type_traits>

#include "sim/core/parallel.h"
#include "sim/mpm/apic_stencil.h"

namespace shellmpm {
namespace {

// Kirchhoff stresses of one particle block, in block order, computed in SIMD batches
// over runs of particles that share a material.
// First position in block b's slice of grid.order that holds a bulk particle (indices
// ascend within a block, other points come first).
std::uint32_t bulk_begin(const SparseGrid& grid, const TransferParams& tp, std::size_t b) {
  const std::uint32_t s0 = grid.pblock_start[b], s1 = grid.pblock_start[b + 1];
  if (tp.first_bulk == 0) return s0;
  const auto* o = grid.order.data();
  return static_cast<std::uint32_t>(std::lower_bound(o + s0, o + s1, tp.first_bulk) - o);
}

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
    const Mat3& tau = tau_local[s - s0];
    // Affine term in grid units: world dpos = dx * (node - fx).
    Mat3 A = (m * dx) * p.C[q];
    Mat3 S = Mat3::Zero();
    if (kMls)
      A -= (Real(4) * dt * vol / dx) * tau;  // MLS: -dt V0 M^-1 tau, M^-1 = 4/dx^2
    else
      S = (dt * vol / dx) * tau;  // APIC: -dt V0 tau grad w, grad w = dw_grid / dx
    const Vec3 fx(W.fx[0], W.fx[1], W.fx[2]);
    apic_scatter<!kMls>(buf.data(), W, bc, m, m * p.v[q] - A * fx, A, S);
  }
}

template <bool kMls>
void g2p_block(ParticleSet& p, SparseGrid& grid, const TransferParams& tp, std::size_t b) {
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

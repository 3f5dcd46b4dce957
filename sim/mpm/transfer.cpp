#include "sim/mpm/transfer.h"

#include <algorithm>
#include <cstring>

#include "sim/core/parallel.h"
#include "sim/mpm/bspline.h"

namespace shellmpm {
namespace {

// Kirchhoff stresses of one particle block, in block order, computed in SIMD batches
// over runs of particles that share a material.
void block_stresses(const ParticleSet& p, const SparseGrid& grid, const TransferParams& tp,
                    std::size_t b, std::vector<Mat3>& F, std::vector<Real>& pl,
                    std::vector<Mat3>& tau) {
  const std::uint32_t s0 = grid.pblock_start[b], s1 = grid.pblock_start[b + 1];
  const std::size_t n = s1 - s0;
  F.resize(n);
  pl.resize(n);
  tau.resize(n);
  const bool plastic = p.has_plastic();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t q = grid.order[s0 + i];
    F[i] = p.F[q];
    pl[i] = plastic ? p.plastic[q] : Real(0);
  }
  if (!tp.stress) {
    std::fill(tau.begin(), tau.end(), Mat3::Zero());
    return;
  }
  std::size_t i = 0;
  while (i < n) {
    const auto mat = p.material[grid.order[s0 + i]];
    std::size_t j = i + 1;
    while (j < n && p.material[grid.order[s0 + j]] == mat) ++j;
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
  const std::uint32_t s0 = grid.pblock_start[b];
  for (std::uint32_t s = s0; s < grid.pblock_start[b + 1]; ++s) {
    const std::uint32_t q = grid.order[s];
    const QuadraticWeights W(grid.grid_coord(p.x[q]));
    const Real vol = p.volume[q];
    const Real m = vol * rho[p.material[q]];
    const Mat3& tau = tau_local[s - s0];
    // Affine term in grid units: dpos_grid = node - fx, world dpos = dx * dpos_grid.
    Mat3 A = (m * dx) * p.C[q];
    Mat3 S = Mat3::Zero();
    if (kMls)
      A -= (Real(4) * dt * vol / dx) * tau;  // MLS: -dt V0 M^-1 tau, M^-1 = 4/dx^2
    else
      S = (dt * vol / dx) * tau;  // APIC: -dt V0 tau grad w, grad w = dw_grid / dx
    const Vec3 mv = m * p.v[q];
    const int lx = W.base[0] - bc[0], ly = W.base[1] - bc[1], lz = W.base[2] - bc[2];
    for (int i = 0; i < 3; ++i) {
      const Real dxg = Real(i) - W.fx[0];
      for (int j = 0; j < 3; ++j) {
        const Real dyg = Real(j) - W.fx[1];
        const Real wxy = W.w[0][i] * W.w[1][j];
        for (int k = 0; k < 3; ++k) {
          const Real dzg = Real(k) - W.fx[2];
          const Real w = wxy * W.w[2][k];
          Vec3 mom = w * (mv + A * Vec3(dxg, dyg, dzg));
          if (!kMls) {
            const Vec3 gw(W.dw[0][i] * W.w[1][j] * W.w[2][k], W.w[0][i] * W.dw[1][j] * W.w[2][k],
                          wxy * W.dw[2][k]);
            mom -= S * gw;
          }
          GridNode& nd = buf[pad_node(lx + i, ly + j, lz + k)];
          nd.m += w * m;
          nd.v[0] += mom[0];
          nd.v[1] += mom[1];
          nd.v[2] += mom[2];
        }
      }
    }
  }
}

template <bool kMls>
void g2p_block(ParticleSet& p, SparseGrid& grid, const TransferParams& tp, std::size_t b) {
  const auto& buf = grid.pblock_buf[b];
  const Vec3i bc = unpack_block(grid.pblock_key[b]) * kBlockSize;
  const Real dx = static_cast<Real>(grid.dx());
  const Real inv_dx = Real(1) / dx;
  const Real dt = tp.dt;
  for (std::uint32_t s = grid.pblock_start[b]; s < grid.pblock_start[b + 1]; ++s) {
    const std::uint32_t q = grid.order[s];
    const QuadraticWeights W(grid.grid_coord(p.x[q]));
    const int lx = W.base[0] - bc[0], ly = W.base[1] - bc[1], lz = W.base[2] - bc[2];
    Vec3 v = Vec3::Zero();
    Mat3 B = Mat3::Zero();  // sum w v (node - fx)^T, grid units
    Mat3 G = Mat3::Zero();  // sum v grad_w^T, grid units
    for (int i = 0; i < 3; ++i) {
      const Real dxg = Real(i) - W.fx[0];
      for (int j = 0; j < 3; ++j) {
        const Real dyg = Real(j) - W.fx[1];
        const Real wxy = W.w[0][i] * W.w[1][j];
        for (int k = 0; k < 3; ++k) {
          const Real dzg = Real(k) - W.fx[2];
          const Real w = wxy * W.w[2][k];
          const GridNode& nd = buf[pad_node(lx + i, ly + j, lz + k)];
          const Vec3 vi(nd.v[0], nd.v[1], nd.v[2]);
          v += w * vi;
          B += (w * vi) * Vec3(dxg, dyg, dzg).transpose();
          if (!kMls) {
            const Vec3 gw(W.dw[0][i] * W.w[1][j] * W.w[2][k], W.w[0][i] * W.dw[1][j] * W.w[2][k],
                          wxy * W.dw[2][k]);
            G += vi * gw.transpose();
          }
        }
      }
    }
    // C = B D^-1 with D = dx^2/4 I; B in world units is dx * B_grid.
    const Mat3 C = (Real(4) * inv_dx) * B;
    const Mat3 gradv = kMls ? C : Mat3(inv_dx * G);
    p.v[q] = v;
    p.C[q] = C;
    p.x[q] += dt * v;
    p.F[q] = (Mat3::Identity() + dt * gradv) * p.F[q];
  }
}

}  // namespace

void particles_to_grid(const ParticleSet& p, SparseGrid& grid, const TransferParams& tp) {
  parallel_for(
      grid.num_particle_blocks(), 1,
      [&](std::size_t bb, std::size_t be) {
        for (std::size_t b = bb; b < be; ++b) {
          if (tp.mls)
            p2g_block<true>(p, grid, tp, b);
          else
            p2g_block<false>(p, grid, tp, b);
        }
      },
      tp.serial);
  grid.gather_buffers_to_grid(tp.serial);
}

void grid_to_particles(ParticleSet& p, SparseGrid& grid, const TransferParams& tp) {
  grid.scatter_grid_to_buffers(tp.serial);
  parallel_for(
      grid.num_particle_blocks(), 1,
      [&](std::size_t bb, std::size_t be) {
        for (std::size_t b = bb; b < be; ++b) {
          if (tp.mls)
            g2p_block<true>(p, grid, tp, b);
          else
            g2p_block<false>(p, grid, tp, b);
        }
      },
      tp.serial);
}

}  // namespace shellmpm

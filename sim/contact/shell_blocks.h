// The per-block loops of the shells' transfers (sim/contact/shell_transfer.h) for one
// particle block: the control points' APIC P2G and G2P, the contact sites' G2P (a3E
// advected with the mass-weighted gradient) and their normal forces. The library compiles
// them for x86-64-v2 (shell_transfer.cpp); shell_blocks_avx2.cpp and
// shell_blocks_avx512.cpp compile the same functions for wider units (the stencil rows of
// sim/mpm/stencil_row.h and the site dots of site_dots.h in one register), with no
// contraction into fused multiply-adds, and shell_transfer.cpp picks one at run time
// (simd_level()). Every instruction set gives the same bits
// (tests/sim/contact/test_contact_solver.cpp, "bit-identical on every
// instruction set"). Internal to sim/contact.
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "sim/contact/shell_transfer.h"
#include "sim/contact/site_dots.h"
#include "sim/mpm/apic_stencil.h"

namespace shellmpm::shell_blocks {

#define SHELLMPM_BLOCKS_INLINE [[gnu::always_inline]] inline

/// Points ahead of the one a block's loop is at whose data it prefetches.
constexpr std::uint32_t kAhead = 8;

/// Slice of block b's order entries holding shell points of one kind: [lo, hi). (The
/// functions here take grid.order() as `order`: its check would make the per-ISA objects
/// define the exception's inline members.)
SHELLMPM_BLOCKS_INLINE std::pair<std::uint32_t, std::uint32_t> slice(const SparseGrid& grid,
                                                                     const std::uint32_t* o,
                                                                     std::size_t b,
                                                                     std::uint32_t lo_index,
                                                                     std::uint32_t hi_index) {
  const std::uint32_t s0 = grid.pblock_start[b], s1 = grid.pblock_start[b + 1];
  const auto lo = std::lower_bound(o + s0, o + s1, lo_index) - o;
  const auto hi = std::lower_bound(o + lo, o + s1, hi_index) - o;
  return {static_cast<std::uint32_t>(lo), static_cast<std::uint32_t>(hi)};
}

/// Up to kSiteLanes contact sites of a particle block whose gradient dots are taken
/// together: their table slots, weights, node masses (from the block's pad) and a3E.
struct SiteBatch {
  int n = 0;
  std::uint32_t slot[kSiteLanes];
  QuadraticWeights W[kSiteLanes];
  SiteLaneInputs in;
  alignas(32) Real dots[27][kSiteLanes];
  bool any[kSiteLanes];
  /// Adds site `slot` at grid coordinates g with normal column a3e; true when the batch
  /// is full.
  SHELLMPM_BLOCKS_INLINE bool add(std::uint32_t s, const Vec3& g, const Vec3& a3e, const Vec3i& bc,
                                  const GridNode* pad) {
    slot[n] = s;
    W[n] = QuadraticWeights(g);
    in.set(n, W[n], a3e);
    int k = 0;
    for_each_stencil_node(W[n], bc, [&](const StencilNode& nd) { in.m[k++][n] = pad[nd.pad()].m; });
    return ++n == kSiteLanes;
  }
};

/// Calls f(g, W, dots, j) for the contact sites in slots [lo, hi) of a particle block
/// (corner bc, node masses in pad), in slot order, their gradient dots with a3E taken
/// kSiteLanes at a time (weighted: g_n . a3E, else without the factor a_n): dots[k][j]
/// for stencil node k; g is the site's point in the table. Sites where skip(g) and sites
/// without a node with mass are left out.
template <class Skip, class F>
SHELLMPM_BLOCKS_INLINE void for_each_site_dots(const SparseGrid& grid, const std::uint32_t* order,
                                               const ShellPointTable& table,
                                               const std::vector<GridShell>& shells,
                                               std::uint32_t lo, std::uint32_t hi, const Vec3i& bc,
                                               const GridNode* pad, bool weighted, Skip skip, F f) {
  const Real dx = static_cast<Real>(grid.dx());
  const bool forces = !weighted;
  SiteBatch batch;
  auto flush = [&]() {
    site_dots::dots_lanes<site_dots::Lanes>(batch.in, batch.n, dx, weighted, batch.dots, batch.any);
    for (int i = 0; i < batch.n; ++i)
      if (batch.any[i]) f(order[batch.slot[i]], batch.W[i], batch.dots, i);
    batch.n = 0;
  };
  for (std::uint32_t s = lo; s < hi; ++s) {
    if (s + kAhead < hi) {
      const std::uint32_t ga = order[s + kAhead];
      const ShellContact& ca = *shells[table.shell(ga)].contact;
      const std::uint32_t pa = table.local(ga);
      __builtin_prefetch(&ca.x[pa]);
      __builtin_prefetch(&ca.a3e[pa]);
      if (forces) {
        __builtin_prefetch(&ca.G3[pa]);
        __builtin_prefetch(&ca.volume[pa]);
      }
    }
    const std::uint32_t g = order[s];
    if (skip(g)) continue;
    const ShellContact& c = *shells[table.shell(g)].contact;
    const std::uint32_t p = table.local(g);
    if (batch.add(s, grid.grid_coord(c.x[p]), c.a3e[p], bc, pad)) flush();
  }
  if (batch.n) flush();
}

/// A node of a padded buffer of fold heights: the mass, the least height and minus the
/// greatest (so that one min keeps both), and a spare lane.
struct HeightsPadNode {
  Real m, hmin, nhmax, spare;
};
/// Three such nodes, a stencil row (i, j, 0..2), in lanes 4k .. 4k + 3, and in lanes
/// 12..15 the buffer's next node, passed through unchanged.
typedef Real HeightsRow __attribute__((vector_size(16 * sizeof(Real))));

/// A control point's fold heights (shell_p2g_block) into a padded buffer (one spare node
/// past its end): the mass m with weight w at every stencil node, and the node's height
/// over the point's tangent plane (unit normal n turned to align's side, at grid
/// coordinate fx) where w > 0, the same IEEE operations as one node at a time.
SHELLMPM_BLOCKS_INLINE void scatter_heights(HeightsPadNode* pad, const QuadraticWeights& W,
                                            const Vec3i& bc, Real m, const Vec3& n,
                                            const Vec3& align) {
  using Mask = decltype(HeightsRow{} > HeightsRow{});
  const Real sign = n.dot(align) >= 0 ? Real(1) : Real(-1);
  const Real fx[3] = {W.fx[0], W.fx[1], W.fx[2]};
  HeightsRow wz{}, hz{}, flip{};
  Mask is_m{}, is_h{};
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 4; ++c) {
      wz[4 * k + c] = W.w[2][k];
      hz[4 * k + c] = n[2] * (Real(k) - fx[2]);
      flip[4 * k + c] = c == 2 ? Real(-1) : Real(1);
      is_m[4 * k + c] = c == 0 ? -1 : 0;
      is_h[4 * k + c] = c == 1 || c == 2 ? -1 : 0;
    }
  const HeightsRow none = HeightsRow{} + std::numeric_limits<Real>::infinity();
  const int lx = W.base[0] - bc[0], ly = W.base[1] - bc[1], lz = W.base[2] - bc[2];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      // n . ((i, j, k) - fx), summed in this order (ShellFields::side_of).
      const Real side_ij = n[0] * (Real(i) - fx[0]) + n[1] * (Real(j) - fx[1]);
      const HeightsRow w = (W.w[0][i] * W.w[1][j]) * wz;
      const HeightsRow h = sign * (side_ij + hz);
      const HeightsRow cand = w > 0 ? h * flip : none;  // lanes 4k + 1: h, 4k + 2: -h
      HeightsPadNode* row = pad + pad_node(lx + i, ly + j, lz);
      HeightsRow a;
      std::memcpy(&a, row, sizeof a);
      const HeightsRow sum = a + w * m;
      const HeightsRow low = cand < a ? cand : a;
      a = is_m ? sum : (is_h ? low : a);
      std::memcpy(row, &a, sizeof a);
    }
}

/// Adds the nodes of particle block b's padded buffer of heights that its points reached
/// (all inside box) into the grid's (FoldHeights::ready). Nodes of the box no point
/// reached hold (0, max, max), which add nothing: so every node of the box is merged,
/// without a test per node, and the grid blocks the box overlaps are made ready.
SHELLMPM_BLOCKS_INLINE void merge_heights(const SparseGrid& grid, std::size_t b,
                                          const HeightsPadNode* pad, const PadBox& box,
                                          FoldHeights& heights) {
  bool spread = false;
  for (int o = 0; o < 8; ++o) {
    int oo[3], lo[3], hi[3];
    if (!box.in_octant(o, oo, lo, hi)) continue;
    const auto g = static_cast<std::size_t>(grid.pblock_nbr[b][o]);
    if (!heights.ready[g]) {
      heights.blocks[g].fill(kNoHeights);
      heights.ready[g] = 1;
    }
    NodeHeights* nodes = heights.blocks[g].data();
    for (int i = lo[0]; i < hi[0]; ++i)
      for (int j = lo[1]; j < hi[1]; ++j)
        for (int k = lo[2]; k < hi[2]; ++k) {
          const HeightsPadNode& p = pad[pad_node(i, j, k)];
          NodeHeights& d = nodes[block_node(i - oo[0], j - oo[1], k - oo[2])];
          d.m += p.m;
          d.hmin = std::min(d.hmin, p.hmin);
          d.hmax = std::max(d.hmax, -p.nhmax);
          spread |= heights_spread(d);
        }
  }
  if (spread) heights.spread.store(true, std::memory_order_relaxed);
}

/// Prefetches what the control points' P2G (with heights where not null: the normal) and
/// G2P read of control point g.
SHELLMPM_BLOCKS_INLINE void prefetch_control_point(const ShellPointTable& table,
                                                   const std::vector<GridShell>& shells,
                                                   std::uint32_t g, const FoldHeights* heights) {
  const GridShell& gs = shells[table.shell(g)];
  const std::uint32_t j = table.local(g);
  __builtin_prefetch(&gs.shell->x[j]);
  __builtin_prefetch(&gs.shell->v[j]);
  __builtin_prefetch(&gs.contact->C[j]);
  __builtin_prefetch(&gs.force[j]);
  __builtin_prefetch(&gs.shell->mass[j]);
  if (heights) __builtin_prefetch(&heights->normal[j]);
}

/// shell_p2g_block's loop.
SHELLMPM_BLOCKS_INLINE void p2g(const SparseGrid& grid, const std::uint32_t* order,
                                const ShellPointTable& table, const std::vector<GridShell>& shells,
                                Real dt, std::size_t b, GridNode* buf, FoldHeights* heights,
                                PadBox& box) {
  const auto [lo, hi] = slice(grid, order, b, 0, table.num_control_points());
  if (lo == hi) return;
  const Vec3i bc = unpack_block(grid.pblock_key[b]) * kBlockSize;
  const Real dx = static_cast<Real>(grid.dx());
  HeightsPadNode hpad[kPadNodes + 1];
  if (heights)
    std::fill(hpad, hpad + kPadNodes + 1,
              HeightsPadNode{Real(0), std::numeric_limits<Real>::max(),
                             std::numeric_limits<Real>::max(), Real(0)});
  for (std::uint32_t s = lo; s < hi; ++s) {
    if (s + kAhead < hi) prefetch_control_point(table, shells, order[s + kAhead], heights);
    const std::uint32_t g = order[s];
    const GridShell& gs = shells[table.shell(g)];
    const std::uint32_t j = table.local(g);
    const ShellObject& sh = *gs.shell;
    const Real m = sh.mass[j];
    const QuadraticWeights W(grid.grid_coord(sh.x[j]));
    const Mat3 A = (m * dx) * gs.contact->C[j];  // world offset = dx (node - fx)
    const Vec3 fx(W.fx[0], W.fx[1], W.fx[2]);
    apic_scatter<false>(buf, W, bc, m, m * sh.v[j] + dt * gs.force[j] - A * fx, A, Mat3::Zero());
    box.add_stencil(W.base[0] - bc[0], W.base[1] - bc[1], W.base[2] - bc[2]);
    if (heights) scatter_heights(hpad, W, bc, m, heights->normal[j], heights->align);
  }
  if (heights) merge_heights(grid, b, hpad, box, *heights);
}

/// shell_g2p_block's loop.
SHELLMPM_BLOCKS_INLINE void g2p(const SparseGrid& grid, const std::uint32_t* order,
                                const ShellPointTable& table, std::vector<GridShell>& shells,
                                Real dt, std::size_t b, const GridNode* buf) {
  const std::uint32_t nc = table.num_control_points();
  const auto [lo, hi] = slice(grid, order, b, 0, static_cast<std::uint32_t>(table.size()));
  if (lo == hi) return;
  const Vec3i bc = unpack_block(grid.pblock_key[b]) * kBlockSize;
  const Real dx = static_cast<Real>(grid.dx());
  const Real c_scale = Real(4) / dx;  // C = B D^-1 with B in grid units times dx
  // The block's control points come first in its slice (the order ascends within a block).
  std::uint32_t s = lo;
  for (; s < hi && order[s] < nc; ++s) {
    if (s + kAhead < hi && order[s + kAhead] < nc)
      prefetch_control_point(table, shells, order[s + kAhead], nullptr);
    const std::uint32_t g = order[s];
    GridShell& gs = shells[table.shell(g)];
    const std::uint32_t j = table.local(g);
    ShellObject& sh = *gs.shell;
    const QuadraticWeights W(grid.grid_coord(sh.x[j]));
    const ApicGather G = apic_gather<false>(buf, W, bc);
    const Vec3& v = G.v;
    gs.contact->C[j] = c_scale * G.B;
    const std::uint8_t held = gs.held[j];
    if (held) {
      // The pin makes up the difference (pin_transfer_work).
      for (int a = 0; a < 3; ++a)
        if (held & (1u << a)) gs.pin_impulse[j][a] = sh.mass[j] * (sh.v[j][a] - v[a]);
    }
    for (int a = 0; a < 3; ++a)
      if (!(held & (1u << a))) sh.v[j][a] = v[a];
    sh.x[j] += dt * sh.v[j];
  }
  // Contact particles, their gradient dots kSiteLanes at a time: grad~v a3E =
  // sum_n v_n (g_n . a3E) (nodes without mass have g_n = 0), summed over the stencil rows
  // as (m, v) per node (the velocity is lanes 1..3).
  for_each_site_dots(
      grid, order, table, shells, s, hi, bc, buf, true, [](std::uint32_t) { return false; },
      [&](std::uint32_t g, const QuadraticWeights& W, const Real(&ga)[27][kSiteLanes], int lane) {
        using namespace stencil_row;
        const int lx = W.base[0] - bc[0], ly = W.base[1] - bc[1], lz = W.base[2] - bc[2];
        Row sum = zero();
        int k = 0;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j, k += 3) {
            const Real g3[3] = {ga[k][lane], ga[k + 1][lane], ga[k + 2][lane]};
            sum = sum + per_node(g3) * load(&buf[pad_node(lx + i, ly + j, lz)]);
          }
        alignas(16) Real v[4];
        node_sum(sum, v);
        ShellContact& c = *shells[table.shell(g)].contact;
        c.a3e[table.local(g)] += dt * Vec3(v[1], v[2], v[3]);
      });
}

/// The normal forces of block b's contact sites [lo, hi) (contact_normal_forces), those g
/// with push[g] (dpsi/da3E != 0): node masses from pad, velocity increments added into
/// inc. Returns whether any site added.
SHELLMPM_BLOCKS_INLINE bool normal_forces(const SparseGrid& grid, const std::uint32_t* order,
                                          const ShellPointTable& table,
                                          const std::vector<GridShell>& shells,
                                          const std::uint8_t* push, Real dt, std::size_t b,
                                          std::uint32_t lo, std::uint32_t hi, const GridNode* pad,
                                          GridNode* inc) {
  bool added = false;
  const Vec3i bc = unpack_block(grid.pblock_key[b]) * kBlockSize;
  for_each_site_dots(
      grid, order, table, shells, lo, hi, bc, pad, false,
      [&](std::uint32_t g) { return !push[g]; },  // no force
      [&](std::uint32_t g, const QuadraticWeights& W, const Real(&t)[27][kSiteLanes], int lane) {
        using namespace stencil_row;
        const ShellContact& c = *shells[table.shell(g)].contact;
        const std::uint32_t p = table.local(g);
        // dt f_n / m_n = -dt V (g_n . a3E) / m_n G3 with g_n / m_n = w_n Minv (d_n - dbar):
        // w_n t_n (0, S) per node with mass, t_n = (d_n - dbar) . Minv^T a3E,
        // S = -dt V G3.
        const Row S = splat(Real(0), (-dt * c.volume[p]) * c.G3[p]);
        const int lx = W.base[0] - bc[0], ly = W.base[1] - bc[1], lz = W.base[2] - bc[2];
        int k = 0;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            const int row = pad_node(lx + i, ly + j, lz);
            Real f[3];
            for (int l = 0; l < 3; ++l, ++k)
              f[l] =
                  pad[row + l].m > 0 ? (W.w[0][i] * W.w[1][j] * W.w[2][l]) * t[k][lane] : Real(0);
            store(&inc[row], load(&inc[row]) + per_node(f) * S);
          }
        added = true;
      });
  return added;
}

/// The per-ISA entry points (shell_blocks_avx2.cpp, shell_blocks_avx512.cpp).
#define SHELLMPM_SHELL_BLOCKS_DECLARE(isa)                                                         \
  void p2g_##isa(const SparseGrid& grid, const std::uint32_t* order, const ShellPointTable& table, \
                 const std::vector<GridShell>& shells, Real dt, std::size_t b, GridNode* buf,      \
                 FoldHeights* heights, PadBox& box);                                               \
  void g2p_##isa(const SparseGrid& grid, const std::uint32_t* order, const ShellPointTable& table, \
                 std::vector<GridShell>& shells, Real dt, std::size_t b, const GridNode* buf);     \
  bool normal_forces_##isa(const SparseGrid& grid, const std::uint32_t* order,                     \
                           const ShellPointTable& table, const std::vector<GridShell>& shells,     \
                           const std::uint8_t* push, Real dt, std::size_t b, std::uint32_t lo,     \
                           std::uint32_t hi, const GridNode* pad, GridNode* inc);
SHELLMPM_SHELL_BLOCKS_DECLARE(avx2)
SHELLMPM_SHELL_BLOCKS_DECLARE(avx512)

}  // namespace shellmpm::shell_blocks

#define SHELLMPM_SHELL_BLOCKS_ENTRIES(isa)                                                        \
  namespace shellmpm::shell_blocks {                                                              \
  __attribute__((flatten)) void p2g_##isa(const SparseGrid& grid, const std::uint32_t* order,     \
                                          const ShellPointTable& table,                           \
                                          const std::vector<GridShell>& shells, Real dt,          \
                                          std::size_t b, GridNode* buf, FoldHeights* heights,     \
                                          PadBox& box) {                                          \
    p2g(grid, order, table, shells, dt, b, buf, heights, box);                                    \
  }                                                                                               \
  __attribute__((flatten)) void g2p_##isa(const SparseGrid& grid, const std::uint32_t* order,     \
                                          const ShellPointTable& table,                           \
                                          std::vector<GridShell>& shells, Real dt, std::size_t b, \
                                          const GridNode* buf) {                                  \
    g2p(grid, order, table, shells, dt, b, buf);                                                  \
  }                                                                                               \
  __attribute__((flatten)) bool normal_forces_##isa(                                              \
      const SparseGrid& grid, const std::uint32_t* order, const ShellPointTable& table,           \
      const std::vector<GridShell>& shells, const std::uint8_t* push, Real dt, std::size_t b,     \
      std::uint32_t lo, std::uint32_t hi, const GridNode* pad, GridNode* inc) {                   \
    return normal_forces(grid, order, table, shells, push, dt, b, lo, hi, pad, inc);              \
  }                                                                                               \
  }

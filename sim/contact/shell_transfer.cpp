#include "sim/contact/shell_transfer.h"

#include <algorithm>
#include <cstring>

#include "sim/collider/collider.h"
#include "sim/core/check.h"
#include "sim/core/parallel.h"
#include "sim/mpm/apic_stencil.h"

namespace shellmpm {

void ShellPointTable::build(const std::vector<GridShell>& shells) {
  shell_.clear();
  local_.clear();
  for (std::size_t s = 0; s < shells.size(); ++s)
    for (std::size_t j = 0; j < shells[s].shell->size(); ++j) {
      shell_.push_back(static_cast<std::uint16_t>(s));
      local_.push_back(static_cast<std::uint32_t>(j));
    }
  num_ctrl_ = static_cast<std::uint32_t>(shell_.size());
  for (std::size_t s = 0; s < shells.size(); ++s)
    for (std::size_t p = 0; p < shells[s].contact->num_sites(); ++p) {
      shell_.push_back(static_cast<std::uint16_t>(s));
      local_.push_back(static_cast<std::uint32_t>(p));
    }
}

void ShellPointTable::positions(const std::vector<GridShell>& shells,
                                std::vector<Vec3>& out) const {
  out.clear();
  out.reserve(size());
  for (const GridShell& g : shells) out.insert(out.end(), g.shell->x.begin(), g.shell->x.end());
  for (const GridShell& g : shells) out.insert(out.end(), g.contact->x.begin(), g.contact->x.end());
}

void ShellPointTable::velocities(const std::vector<GridShell>& shells,
                                 std::vector<Vec3>& out) const {
  out.clear();
  out.reserve(size());
  for (const GridShell& g : shells) out.insert(out.end(), g.shell->v.begin(), g.shell->v.end());
  out.resize(size(), Vec3::Zero());
}

void prescribe_pins(ShellObject& sh, double t, double dt, std::vector<std::uint8_t>& held) {
  const ShellDesc& d = sh.desc();
  held.assign(sh.size(), 0);
  if (d.pins.empty()) return;
  std::vector<RigidPose> poses(d.pins.size());
  std::vector<char> released(d.pins.size());
  for (std::size_t p = 0; p < poses.size(); ++p) {
    poses[p] = keyframe_pose(d.pins[p].keyframes, t + dt);
    released[p] = d.pins[p].release_time && t >= *d.pins[p].release_time;
  }
  const Real h = static_cast<Real>(dt);
  for (std::size_t i = 0; i < sh.size(); ++i) {
    if (!sh.pin_mask[i] || released[sh.pin_of[i]]) continue;
    const Vec3 target = poses[sh.pin_of[i]].apply(sh.rest[i]).cast<Real>();
    held[i] = sh.pin_mask[i];
    for (int a = 0; a < 3; ++a)
      if (held[i] & (1u << a)) sh.v[i][a] = (target[a] - sh.x[i][a]) / h;
  }
}

namespace {

// Slice of block b's order entries holding shell points of one kind: [lo, hi).
std::pair<std::uint32_t, std::uint32_t> slice(const SparseGrid& grid, std::size_t b,
                                              std::uint32_t lo_index, std::uint32_t hi_index) {
  const auto* o = grid.order().data();
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
  bool add(std::uint32_t s, const Vec3& g, const Vec3& a3e, const Vec3i& bc, const GridNode* pad) {
    slot[n] = s;
    W[n] = QuadraticWeights(g);
    in.set(n, W[n], a3e);
    int k = 0;
    for_each_stencil_node(W[n], bc, [&](const StencilNode& nd) { in.m[k++][n] = pad[nd.pad()].m; });
    return ++n == kSiteLanes;
  }
};

/// Calls f(g, W, dots, j) for the contact sites in slots [lo, hi) of particle block b
/// (corner bc, node masses in pad), in slot order, their gradient dots with a3E taken
/// kSiteLanes at a time (site_dots_batch; weighted: g_n . a3E, else without the factor
/// a_n): dots[k][j] for stencil node k; g is the site's point in the table. Sites where
/// skip(g) and sites without a node with mass are left out.
template <class Skip, class F>
void for_each_site_dots(const SparseGrid& grid, const ShellPointTable& table,
                        const std::vector<GridShell>& shells, std::uint32_t lo, std::uint32_t hi,
                        const Vec3i& bc, const GridNode* pad, bool weighted, Skip skip, F f) {
  const std::vector<std::uint32_t>& order = grid.order();
  const Real dx = static_cast<Real>(grid.dx());
  SiteBatch batch;
  auto flush = [&]() {
    site_dots_batch(batch.in, batch.n, dx, weighted, batch.dots, batch.any);
    for (int i = 0; i < batch.n; ++i)
      if (batch.any[i]) f(order[batch.slot[i]], batch.W[i], batch.dots, i);
    batch.n = 0;
  };
  for (std::uint32_t s = lo; s < hi; ++s) {
    const std::uint32_t g = order[s];
    if (skip(g)) continue;
    const ShellContact& c = *shells[table.shell(g)].contact;
    const std::uint32_t p = table.local(g);
    if (batch.add(s, grid.grid_coord(c.x[p]), c.a3e[p], bc, pad)) flush();
  }
  if (batch.n) flush();
}

}  // namespace

void shell_p2g_block(const SparseGrid& grid, const ShellPointTable& table,
                     const std::vector<GridShell>& shells, Real dt, std::size_t b, GridNode* buf) {
  const auto [lo, hi] = slice(grid, b, 0, table.num_control_points());
  if (lo == hi) return;
  const std::vector<std::uint32_t>& order = grid.order();
  const Vec3i bc = unpack_block(grid.pblock_key[b]) * kBlockSize;
  const Real dx = static_cast<Real>(grid.dx());
  for (std::uint32_t s = lo; s < hi; ++s) {
    const std::uint32_t g = order[s];
    const GridShell& gs = shells[table.shell(g)];
    const std::uint32_t j = table.local(g);
    const ShellObject& sh = *gs.shell;
    const Real m = sh.mass[j];
    const QuadraticWeights W(grid.grid_coord(sh.x[j]));
    const Mat3 A = (m * dx) * gs.contact->C[j];  // world offset = dx (node - fx)
    const Vec3 fx(W.fx[0], W.fx[1], W.fx[2]);
    apic_scatter<false>(buf, W, bc, m, m * sh.v[j] + dt * gs.force[j] - A * fx, A, Mat3::Zero());
  }
}

void shell_g2p_block(const SparseGrid& grid, const ShellPointTable& table,
                     std::vector<GridShell>& shells, Real dt, std::size_t b, const GridNode* buf) {
  const std::uint32_t nc = table.num_control_points();
  const auto [lo, hi] = slice(grid, b, 0, static_cast<std::uint32_t>(table.size()));
  if (lo == hi) return;
  const std::vector<std::uint32_t>& order = grid.order();
  const Vec3i bc = unpack_block(grid.pblock_key[b]) * kBlockSize;
  const Real dx = static_cast<Real>(grid.dx());
  // The block's control points come first in its slice (the order ascends within a block).
  std::uint32_t s = lo;
  for (; s < hi && order[s] < nc; ++s) {
    const std::uint32_t g = order[s];
    GridShell& gs = shells[table.shell(g)];
    const std::uint32_t j = table.local(g);
    ShellObject& sh = *gs.shell;
    const QuadraticWeights W(grid.grid_coord(sh.x[j]));
    const ApicGather G = apic_gather<false>(buf, W, bc);
    const Vec3& v = G.v;
    gs.contact->C[j] = (Real(4) / dx) * G.B;  // B D^-1 with B in grid units times dx
    const std::uint8_t held = gs.held[j];
    for (int a = 0; a < 3; ++a)
      if (!(held & (1u << a))) sh.v[j][a] = v[a];
    sh.x[j] += dt * sh.v[j];
  }
  // Contact particles, their gradient dots kSiteLanes at a time.
  for_each_site_dots(
      grid, table, shells, s, hi, bc, buf, true, [](std::uint32_t) { return false; },
      [&](std::uint32_t g, const QuadraticWeights& W, const Real(&ga)[27][kSiteLanes], int lane) {
        ShellContact& c = *shells[table.shell(g)].contact;
        const std::uint32_t j = table.local(g);
        // grad~v a3E = sum_n v_n (g_n . a3E); nodes without mass have g_n = 0. The sum of
        // ga[n] (m, v) over the nodes as 4-vectors: the velocity part is lanes 1..3.
        typedef Real R4 __attribute__((vector_size(4 * sizeof(Real))));
        R4 sum = {};
        int n = 0;
        for_each_stencil_node(W, bc, [&](const StencilNode& nd) {
          R4 node;
          std::memcpy(&node, &buf[nd.pad()], sizeof node);
          sum += ga[n++][lane] * node;
        });
        c.a3e[j] += dt * Vec3(sum[1], sum[2], sum[3]);
      });
}

void contact_normal_forces(SparseGrid& grid, const ShellPointTable& table,
                           const std::vector<GridShell>& shells, Real dt, bool serial) {
  const std::uint32_t nc = table.num_control_points();
  const auto ns = static_cast<std::uint32_t>(table.size());
  // Colour by colour (blocks of a colour touch disjoint nodes): each block with contact
  // particles reads its nodes' masses and adds its velocity increments straight into the
  // grid.
  grid.for_each_block_by_colour(
      [&](std::size_t b) {
        const auto [lo, hi] = slice(grid, b, nc, ns);
        if (lo == hi) return;
        GridNode pad[kPadNodes], inc[kPadNodes];
        std::memset(static_cast<void*>(inc), 0, sizeof inc);
        grid.copy_grid_to_pad(b, pad);  // every node of the pad
        bool added = false;
        const Vec3i bc = unpack_block(grid.pblock_key[b]) * kBlockSize;
        for_each_site_dots(
            grid, table, shells, lo, hi, bc, pad, false,
            [&](std::uint32_t g) {  // separated without shear: no force
              return shells[table.shell(g)].contact->G3[table.local(g)].squaredNorm() == 0;
            },
            [&](std::uint32_t g, const QuadraticWeights& W, const Real(&t)[27][kSiteLanes],
                int lane) {
              const ShellContact& c = *shells[table.shell(g)].contact;
              const std::uint32_t p = table.local(g);
              // dt f_n / m_n = -dt V (g_n . a3E) / m_n G3 with g_n / m_n = w_n Minv (d_n -
              // dbar): w_n t_n (0, S) per node, t_n = (d_n - dbar) . Minv^T a3E,
              // S = -dt V G3.
              const Real s0 = -dt * c.volume[p];
              const Vec3& G3 = c.G3[p];
              typedef Real R4 __attribute__((vector_size(4 * sizeof(Real))));
              const R4 S = {Real(0), s0 * G3[0], s0 * G3[1], s0 * G3[2]};
              int n = 0;
              for_each_stencil_node(W, bc, [&](const StencilNode& nd) {
                const int k = n++;
                const int id = nd.pad();
                if (!(pad[id].m > 0)) return;
                R4 acc;
                std::memcpy(&acc, &inc[id], sizeof acc);
                acc += (nd.w * t[k][lane]) * S;
                std::memcpy(&inc[id], &acc, sizeof acc);
              });
              added = true;
            });
        if (added) grid.add_pad_to_grid(b, inc);
      },
      serial);
}

}  // namespace shellmpm

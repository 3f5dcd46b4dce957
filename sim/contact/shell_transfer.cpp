#include "sim/contact/shell_transfer.h"

#include <algorithm>
#include <cstring>

#include "sim/collider/collider.h"
#include "sim/contact/shell_blocks.h"
#include "sim/core/check.h"
#include "sim/core/parallel.h"
#include "sim/mpm/apic_stencil.h"
#include "sim/mpm/stress_batch.h"

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
  single_ = shells.size() == 1;
}

void ShellPointTable::positions(const std::vector<GridShell>& shells, std::vector<Vec3>& out,
                                bool serial) const {
  out.resize(size());
  std::size_t at = 0;
  const auto copy = [&](const std::vector<Vec3>& x) {
    Vec3* to = out.data() + at;
    parallel_for(
        x.size(), 65536,
        [&](std::size_t b, std::size_t e) { std::copy(x.data() + b, x.data() + e, to + b); },
        serial);
    at += x.size();
  };
  for (const GridShell& g : shells) copy(g.shell->x);
  for (const GridShell& g : shells) copy(g.contact->x);
}

void ShellPointTable::velocities(const std::vector<GridShell>& shells,
                                 std::vector<Vec3>& out) const {
  out.clear();
  out.reserve(size());
  for (const GridShell& g : shells) out.insert(out.end(), g.shell->v.begin(), g.shell->v.end());
  out.resize(size(), Vec3::Zero());
}

double prescribe_pins(GridShell& g, double t, double dt) {
  ShellObject& sh = *g.shell;
  std::vector<std::uint8_t>& held = g.held;
  const ShellDesc& d = sh.desc();
  held.assign(sh.size(), 0);
  g.pin_impulse.clear();
  if (d.pins.empty()) return 0.0;
  std::vector<RigidPose> poses(d.pins.size());
  std::vector<char> released(d.pins.size());
  bool holds = false;
  for (std::size_t p = 0; p < poses.size(); ++p) {
    poses[p] = keyframe_pose(d.pins[p].keyframes, t + dt);
    released[p] = d.pins[p].release_time && t >= *d.pins[p].release_time;
    holds = holds || !released[p];
  }
  if (!holds) return 0.0;
  g.pin_impulse.assign(sh.size(), Vec3::Zero());
  const Real h = static_cast<Real>(dt);
  double work = 0;
  for (std::size_t i = 0; i < sh.size(); ++i) {
    if (!sh.pin_mask[i] || released[sh.pin_of[i]]) continue;
    const Vec3 target = poses[sh.pin_of[i]].apply(sh.rest[i]).cast<Real>();
    held[i] = sh.pin_mask[i];
    for (int a = 0; a < 3; ++a)
      if (held[i] & (1u << a)) {
        const Real v0 = sh.v[i][a];
        sh.v[i][a] = (target[a] - sh.x[i][a]) / h;
        work += static_cast<double>(sh.mass[i]) * static_cast<double>(sh.v[i][a] - v0) *
                static_cast<double>(sh.v[i][a]);
      }
  }
  return work;
}

double pin_transfer_work(const GridShell& g) {
  if (g.pin_impulse.empty()) return 0.0;
  const ShellObject& sh = *g.shell;
  double work = 0;
  for (std::size_t i = 0; i < g.pin_impulse.size(); ++i) {
    const std::uint8_t held = g.held[i];
    if (!held) continue;
    for (int a = 0; a < 3; ++a)
      if (held & (1u << a))
        work += static_cast<double>(g.pin_impulse[i][a]) * static_cast<double>(sh.v[i][a]);
  }
  return work;
}

void shell_p2g_block(const SparseGrid& grid, const ShellPointTable& table,
                     const std::vector<GridShell>& shells, Real dt, std::size_t b, GridNode* buf,
                     FoldHeights* heights, PadBox* box) {
  const std::uint32_t* order = grid.order().data();
  PadBox own;
  PadBox& reached = box ? *box : own;
  switch (simd_level()) {
    case SimdLevel::Avx512:
      return shell_blocks::p2g_avx512(grid, order, table, shells, dt, b, buf, heights, reached);
    case SimdLevel::Avx2:
      return shell_blocks::p2g_avx2(grid, order, table, shells, dt, b, buf, heights, reached);
    case SimdLevel::Sse:
      break;
  }
  shell_blocks::p2g(grid, order, table, shells, dt, b, buf, heights, reached);
}

void shell_g2p_block(const SparseGrid& grid, const ShellPointTable& table,
                     std::vector<GridShell>& shells, Real dt, std::size_t b, const GridNode* buf) {
  const std::uint32_t* order = grid.order().data();
  switch (simd_level()) {
    case SimdLevel::Avx512:
      return shell_blocks::g2p_avx512(grid, order, table, shells, dt, b, buf);
    case SimdLevel::Avx2:
      return shell_blocks::g2p_avx2(grid, order, table, shells, dt, b, buf);
    case SimdLevel::Sse:
      break;
  }
  shell_blocks::g2p(grid, order, table, shells, dt, b, buf);
}

void contact_normal_forces(SparseGrid& grid, const ShellPointTable& table,
                           const std::vector<GridShell>& shells, Real dt, bool serial) {
  const std::uint32_t nc = table.num_control_points();
  const auto ns = static_cast<std::uint32_t>(table.size());
  const std::uint32_t* order = grid.order().data();
  // The sites that push (dpsi/da3E != 0; ShellContact::forces gives the separated ones
  // none), one byte per table entry from nc on, read in one pass over each shell's G3.
  std::vector<std::uint8_t> pushing(ns - nc);
  for (std::size_t i0 = 0, s = 0; s < shells.size(); ++s) {
    const std::vector<Vec3>& G3 = shells[s].contact->G3;
    parallel_for(
        G3.size(), 4096,
        [&](std::size_t b, std::size_t e) {
          for (std::size_t p = b; p < e; ++p) pushing[i0 + p] = G3[p].squaredNorm() != 0;
        },
        serial);
    i0 += G3.size();
  }
  const std::uint8_t* push = pushing.data() - nc;  // push[g] for table entries g >= nc
  // Colour by colour (blocks of a colour touch disjoint nodes): each block with pushing
  // contact particles reads its nodes' masses and adds its velocity increments straight
  // into the grid.
  grid.for_each_block_by_colour(
      [&](std::size_t b) {
        auto [lo, hi] = shell_blocks::slice(grid, order, b, nc, ns);
        while (lo < hi && !push[order[lo]]) ++lo;
        if (lo == hi) return;
        GridNode pad[kPadNodes], inc[kPadNodes];
        std::memset(static_cast<void*>(inc), 0, sizeof inc);
        grid.copy_grid_to_pad(b, pad);  // every node of the pad
        bool added = false;
        switch (simd_level()) {
          case SimdLevel::Avx512:
            added = shell_blocks::normal_forces_avx512(grid, order, table, shells, push, dt, b, lo,
                                                       hi, pad, inc);
            break;
          case SimdLevel::Avx2:
            added = shell_blocks::normal_forces_avx2(grid, order, table, shells, push, dt, b, lo,
                                                     hi, pad, inc);
            break;
          case SimdLevel::Sse:
            added = shell_blocks::normal_forces(grid, order, table, shells, push, dt, b, lo, hi,
                                                pad, inc);
            break;
        }
        if (added) grid.add_pad_to_grid(b, inc);
      },
      serial);
}

}  // namespace shellmpm

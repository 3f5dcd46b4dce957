// Where one shell folds onto itself, two fields for it (see shell_fields.h).
//
// Two layers of the same shell in one node's stencil (a cloth folded over, the halves of
// a twisted strip, the turns of a rolled-up sheet, the walls of a crumple) must meet by
// the contact rule, not share the node's velocity: even a layer that reaches the node
// with a thousandth of its mass is dragged at that rate every step, and a fold that
// should slide at g (sin - c_F cos) slid at a third of it. Every control point tells its
// layer apart by the node's height over its own tangent plane (fold_height): one flat
// layer gives one height at every point, two layers give two, whatever the layers'
// orientation (the normals are turned to a fixed direction first, so a fold whose normals
// face each other counts like stacked turns). P2G keeps each node's least and greatest
// height; where they differ by kFoldMinRange cells or more, the points are split at the
// midpoint into two classes, and each becomes a body of its own for Bardenhagen's rule.
// A single layer curved to a radius under about two cells also spans that range and is
// split between its inner and outer part: harmless, the parts are held together by the
// shell's own forces, and where they do not approach they keep their own velocities as
// a finer transfer would. Everything here runs only on the particle blocks next to split
// nodes.
#include <cstring>

#include "sim/contact/shell_fields.h"
#include "sim/core/parallel.h"
#include "sim/mpm/apic_stencil.h"

namespace shellmpm {

void ShellFields::mark_split_nodes(Field& F, bool heights_only) {
  const std::size_t ng = F.grid.num_grid_blocks();
  F.fold.assign(ng, -1);
  F.folds.clear();
  for (std::size_t g = 0; g < ng; ++g) {
    for (int n = 0; n < kBlockNodes; ++n) {
      NodeHeights d;
      if (heights_only) {
        d = F.heights[g][n];
      } else {
        const Node& f = F.nodes[g][n];
        d = {f.m, f.hmin, f.hmax};
      }
      if (!heights_spread(d)) continue;
      if (F.fold[g] < 0) {
        // Heights only: the full sums of a fold block come from its classes alone.
        if (heights_only) Node::clear(F.nodes[g].data(), kBlockNodes);
        F.fold[g] = static_cast<int>(F.folds.size());
        FoldBlock& fb = F.folds.emplace_back();
        fb.split.fill(0);
        fb.cut.fill(Real(0));
        Node::clear(fb.second.data(), fb.second.size());
        fb.r.fill(Vec3::Zero());
      }
      F.folds[F.fold[g]].split[n] = 1;
      F.folds[F.fold[g]].cut[n] = Real(0.5) * (d.hmin + d.hmax);
    }
  }
}

void ShellFields::scatter_classes(Field& F, const GridShell& gs, Real dt, bool serial) {
  const SparseGrid& G = F.grid;
  const ShellObject& sh = *gs.shell;
  const std::size_t nb = G.num_particle_blocks();
  const Real dx = static_cast<Real>(G.dx());
  // The particle blocks that scatter to a split node.
  F.touched.assign(nb, -1);
  int num_touched = 0;
  for (std::size_t b = 0; b < nb; ++b)
    for (int o = 0; o < 8; ++o) {
      const int g = G.pblock_nbr[b][o];
      if (g >= 0 && F.fold[g] >= 0) {
        F.touched[b] = num_touched++;
        break;
      }
    }
  F.class_buf.resize(num_touched);

  parallel_for_each(
      nb, 1,
      [&](std::size_t b) {
        if (F.touched[b] < 0) return;
        auto& buf = F.class_buf[F.touched[b]];
        for (Classes& c : buf) Node::clear(c.c, 2);
        const Vec3i bc = unpack_block(G.pblock_key[b]) * kBlockSize;
        const auto& nbr = G.pblock_nbr[b];
        for (std::uint32_t q = G.pblock_start[b]; q < G.pblock_start[b + 1]; ++q) {
          const std::uint32_t j = G.order()[q];
          const QuadraticWeights W(G.grid_coord(sh.x[j]));
          const PointShare P(gs, F.normal[j], Vec3(W.fx[0], W.fx[1], W.fx[2]), j, dx, dt, true);
          for_each_stencil_node(W, bc, [&](const StencilNode& n) {
            const int g = nbr[(n.px >> 2) * 4 + (n.py >> 2) * 2 + (n.pz >> 2)];
            if (g < 0 || F.fold[g] < 0) return;
            const FoldBlock& fb = F.folds[F.fold[g]];
            const int bn = block_node(n.px & 3, n.py & 3, n.pz & 3);
            if (!is_split(fb, bn)) return;
            const int c = fold_height(P.n, P.fx, n.i, n.j, n.k) >= fb.cut[bn] ? 1 : 0;
            P.add(buf[n.pad()].c[c], n.w, n.i, n.j, n.k);
          });
        }
      },
      serial);
}

void ShellFields::gather_classes(Field& F, bool serial) {
  const SparseGrid& G = F.grid;
  const std::size_t ng = G.num_grid_blocks();
  parallel_for(
      ng, 4,
      [&](std::size_t gb, std::size_t ge) {
        std::array<Classes, kBlockNodes> sum;
        for (std::size_t g = gb; g < ge; ++g) {
          if (F.fold[g] < 0) continue;
          FoldBlock& fb = F.folds[F.fold[g]];
          for (Classes& c : sum) Node::clear(c.c, 2);
          G.for_each_buffer_node(g, [&](int dn, std::size_t src, int sn) {
            if (F.touched[src] < 0 || !is_split(fb, dn)) return;
            const Classes& s = F.class_buf[F.touched[src]][sn];
            sum[dn].c[0] += s.c[0];
            sum[dn].c[1] += s.c[1];
          });
          for (int n = 0; n < kBlockNodes; ++n) {
            if (!is_split(fb, n)) continue;
            // A node stays whole where one class is empty (one layer: the heights spread
            // only at points of zero weight).
            if (!(sum[n].c[0].m > 0) || !(sum[n].c[1].m > 0)) {
              fb.split[n] = 0;
              continue;
            }
            F.nodes[g][n] = sum[n].c[0];
            fb.second[n] = sum[n].c[1];
          }
        }
      },
      serial);
}

void ShellFields::split_folds(Field& F, const GridShell& gs, Real dt, bool serial) {
  // 1. The nodes whose heights spread: cut at the midpoint.
  mark_split_nodes(F, heights_only_);
  if (F.folds.empty()) return;
  // 2. Both classes, summed as the whole shell was, on the particle blocks that scatter to
  //    a split node; a node stays whole where one class is empty.
  scatter_classes(F, gs, dt, serial);
  gather_classes(F, serial);
}

}  // namespace shellmpm

#include "sim/contact/shell_fields.h"

#include <cstring>

#include "sim/core/parallel.h"
#include "sim/mpm/bspline.h"

namespace shellmpm {

void ShellFields::setup(const SparseGrid& grid, std::size_t num_shells) {
  grids_.clear();
  if (num_shells < 2) return;
  grids_.resize(num_shells);
  for (Field& f : grids_) f.grid.setup(grid.dx(), grid.origin());
}

void ShellFields::p2g(const std::vector<GridShell>& shells, Real dt, bool serial) {
  for (std::size_t s = 0; s < grids_.size(); ++s) {
    Field& F = grids_[s];
    const GridShell& gs = shells[s];
    const ShellObject& sh = *gs.shell;
    F.x0 = sh.x;
    F.grid.bin(sh.x, serial);
    const std::size_t nb = F.grid.num_particle_blocks(), ng = F.grid.num_grid_blocks();
    F.buf.resize(nb);
    F.nodes.resize(ng);
    F.r.resize(ng);
    const Real dx = static_cast<Real>(F.grid.dx());
    parallel_for(
        nb, 1,
        [&](std::size_t bb, std::size_t be) {
          for (std::size_t b = bb; b < be; ++b) {
            auto& buf = F.buf[b];
            std::memset(static_cast<void*>(buf.data()), 0, sizeof(buf));
            const Vec3i bc = unpack_block(F.grid.pblock_key[b]) * kBlockSize;
            for (std::uint32_t q = F.grid.pblock_start[b]; q < F.grid.pblock_start[b + 1]; ++q) {
              const std::uint32_t j = F.grid.order[q];
              const Real m = sh.mass[j];
              const QuadraticWeights W(F.grid.grid_coord(sh.x[j]));
              const Mat3 A = (m * dx) * gs.contact->C[j];
              const Vec3 fx(W.fx[0], W.fx[1], W.fx[2]);
              const Vec3 base = m * sh.v[j] + dt * gs.force[j] - A * fx;
              const int lx = W.base[0] - bc[0], ly = W.base[1] - bc[1], lz = W.base[2] - bc[2];
              for (int i = 0; i < 3; ++i)
                for (int jj = 0; jj < 3; ++jj)
                  for (int k = 0; k < 3; ++k) {
                    const Real w = W.w[0][i] * W.w[1][jj] * W.w[2][k];
                    const Vec3 mom = w * (base + A * Vec3(Real(i), Real(jj), Real(k)));
                    Node& nd = buf[pad_node(lx + i, ly + jj, lz + k)];
                    nd.m += w * m;
                    for (int a = 0; a < 3; ++a) nd.p[a] += mom[a];
                  }
            }
          }
        },
        serial);
    parallel_for(
        ng, 4,
        [&](std::size_t gb, std::size_t ge) {
          for (std::size_t g = gb; g < ge; ++g) {
            auto& nodes = F.nodes[g];
            std::memset(static_cast<void*>(nodes.data()), 0, sizeof(nodes));
            F.r[g].fill(Vec3::Zero());
            F.grid.for_each_buffer_node(g, [&](int dn, std::size_t src, int sn) {
              const Node& from = F.buf[src][sn];
              Node& d = nodes[dn];
              d.m += from.m;
              for (int a = 0; a < 3; ++a) d.p[a] += from.p[a];
            });
            for (Node& d : nodes)
              if (d.m > 0)
                for (Real& p : d.p) p /= d.m;
          }
        },
        serial);
  }
}

void ShellFields::correct(const SparseGrid& combined, std::vector<GridShell>& shells,
                                 Real dt, const SkipFn& skip, bool serial) {
  const std::size_t K = grids_.size();
  // Relative velocities at nodes shared by shells only.
  parallel_for(
      combined.num_grid_blocks(), 4,
      [&](std::size_t gb, std::size_t ge) {
        std::vector<int> fb(K);
        for (std::size_t g = gb; g < ge; ++g) {
          const std::uint64_t key = combined.gblock_key[g];
          int present = 0;
          for (std::size_t s = 0; s < K; ++s) {
            fb[s] = grids_[s].grid.find_grid_block(key);
            if (fb[s] >= 0) ++present;
          }
          if (present < 2) continue;
          const Vec3i c = unpack_block(key) * kBlockSize;
          for (int n = 0; n < kBlockNodes; ++n) {
            const Real m = combined.gblock_nodes[g][n].m;
            if (m <= 0) continue;
            Real ms = 0;
            Vec3 ps = Vec3::Zero();
            int cnt = 0;
            for (std::size_t s = 0; s < K; ++s) {
              if (fb[s] < 0) continue;
              const Node& f = grids_[s].nodes[fb[s]][n];
              if (f.m <= 0) continue;
              ms += f.m;
              ps += f.m * Vec3(f.p[0], f.p[1], f.p[2]);
              ++cnt;
            }
            if (cnt < 2 || ms < Real(0.9999) * m) continue;  // one shell, or bulk material
            if (skip && skip(c + Vec3i(n >> 4, (n >> 2) & 3, n & 3))) continue;
            const Vec3 v0 = ps / ms;
            for (std::size_t s = 0; s < K; ++s) {
              if (fb[s] < 0) continue;
              const Node& f = grids_[s].nodes[fb[s]][n];
              if (f.m > 0) grids_[s].r[fb[s]][n] = Vec3(f.p[0], f.p[1], f.p[2]) - v0;
            }
          }
        }
      },
      serial);
  // Control points read their shell's relative velocity.
  for (std::size_t s = 0; s < K; ++s) {
    Field& F = grids_[s];
    GridShell& gs = shells[s];
    ShellObject& sh = *gs.shell;
    const Real c_scale = Real(4) / static_cast<Real>(F.grid.dx());
    parallel_for(
        F.grid.num_particle_blocks(), 1,
        [&](std::size_t bb, std::size_t be) {
          for (std::size_t b = bb; b < be; ++b) {
            const Vec3i bc = unpack_block(F.grid.pblock_key[b]) * kBlockSize;
            const auto& nbr = F.grid.pblock_nbr[b];
            for (std::uint32_t q = F.grid.pblock_start[b]; q < F.grid.pblock_start[b + 1]; ++q) {
              const std::uint32_t j = F.grid.order[q];
              const QuadraticWeights W(F.grid.grid_coord(F.x0[j]));
              const Vec3 fx(W.fx[0], W.fx[1], W.fx[2]);
              const int lx = W.base[0] - bc[0], ly = W.base[1] - bc[1], lz = W.base[2] - bc[2];
              Vec3 dv = Vec3::Zero();
              Mat3 B = Mat3::Zero();
              bool any = false;
              for (int i = 0; i < 3; ++i)
                for (int jj = 0; jj < 3; ++jj)
                  for (int k = 0; k < 3; ++k) {
                    const int px = lx + i, py = ly + jj, pz = lz + k;
                    const int o = (px >> 2) * 4 + (py >> 2) * 2 + (pz >> 2);
                    const Vec3& rn = F.r[nbr[o]][block_node(px & 3, py & 3, pz & 3)];
                    if (rn.isZero()) continue;
                    any = true;
                    const Real w = W.w[0][i] * W.w[1][jj] * W.w[2][k];
                    dv += w * rn;
                    B += (w * rn) * (Vec3(Real(i), Real(jj), Real(k)) - fx).transpose();
                  }
              if (!any) continue;
              const std::uint8_t held = gs.held[j];
              for (int a = 0; a < 3; ++a)
                if (held & (1u << a)) {
                  dv[a] = 0;
                  B.row(a).setZero();
                }
              sh.v[j] += dv;
              sh.x[j] += dt * dv;
              gs.contact->C[j] += c_scale * B;
            }
          }
        },
        serial);
  }
}

}  // namespace shellmpm

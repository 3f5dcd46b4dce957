#include "sim/mpm/sparse_grid.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "sim/core/check.h"
#include "sim/core/parallel.h"

namespace shellmpm {

void SparseGrid::setup(double dx, const Vec3d& origin) {
  SHELLMPM_CHECK(dx > 0, << dx);
  dx_ = dx;
  inv_dx_ = 1.0 / dx;
  origin_ = origin;
}

void SparseGrid::bin(const std::vector<Vec3>* first, const std::vector<Vec3>& xs, bool serial) {
  const std::size_t n0 = first ? first->size() : 0;
  const std::size_t n = n0 + xs.size();
  auto pos = [&](std::size_t p) -> const Vec3& { return p < n0 ? (*first)[p] : xs[p - n0]; };
  // Runs of consecutive points in one particle block, found in parallel per fixed chunk
  // (points sorted by block, as after every frame's reorder, make few runs).
  const std::size_t nc = (n + kBinChunk - 1) / kBinChunk;
  if (chunk_runs_.size() < nc) chunk_runs_.resize(nc);
  parallel_for_each(
      nc, 1,
      [&](std::size_t c) {
        std::vector<Run>& runs = chunk_runs_[c];
        runs.clear();
        const std::size_t e = std::min(n, (c + 1) * kBinChunk);
        for (std::size_t p = c * kBinChunk; p < e; ++p) {
          const Vec3 g = grid_coord(pos(p));
          const int bx = static_cast<int>(std::floor(g[0] - Real(0.5))) >> 2;
          const int by = static_cast<int>(std::floor(g[1] - Real(0.5))) >> 2;
          const int bz = static_cast<int>(std::floor(g[2] - Real(0.5))) >> 2;
          SHELLMPM_CHECK(
              bx >= 0 && by >= 0 && bz >= 0 && bx < (1 << 19) && by < (1 << 19) && bz < (1 << 19),
              << "particle " << p << " at " << pos(p).transpose() << " is off the grid");
          const std::uint64_t key = pack_block(bx, by, bz);
          if (runs.empty() || runs.back().key != key)
            runs.push_back({key, static_cast<std::uint32_t>(p), 0});
        }
      },
      serial);
  // Block indices follow first appearance in point order; then the stable counting sort
  // by runs: start[] from the run lengths, each run's first slot in order[].
  phash_.clear();
  pblock_key.clear();
  for (std::size_t c = 0; c < nc; ++c)
    for (Run& r : chunk_runs_[c]) {
      const int id = phash_.insert(r.key);
      if (static_cast<std::size_t>(id) == pblock_key.size()) pblock_key.push_back(r.key);
      r.block = static_cast<std::uint32_t>(id);
    }
  const std::size_t nb = pblock_key.size();
  auto run_end = [&](std::size_t c, std::size_t i) -> std::uint32_t {
    const auto& runs = chunk_runs_[c];
    return static_cast<std::uint32_t>(i + 1 < runs.size() ? runs[i + 1].begin
                                                          : std::min(n, (c + 1) * kBinChunk));
  };
  pblock_start.assign(nb + 1, 0);
  for (std::size_t c = 0; c < nc; ++c)
    for (std::size_t i = 0; i < chunk_runs_[c].size(); ++i)
      pblock_start[chunk_runs_[c][i].block + 1] += run_end(c, i) - chunk_runs_[c][i].begin;
  for (std::size_t b = 0; b < nb; ++b) pblock_start[b + 1] += pblock_start[b];
  std::vector<std::uint32_t> cursor(pblock_start.begin(), pblock_start.end() - 1);
  for (std::size_t c = 0; c < nc; ++c)
    for (std::size_t i = 0; i < chunk_runs_[c].size(); ++i) {
      Run& r = chunk_runs_[c][i];
      const std::uint32_t len = run_end(c, i) - r.begin;
      const std::uint32_t slot = cursor[r.block];
      cursor[r.block] += len;
      r.block = slot;  // from here: the run's first slot in order[]
    }
  order.resize(n);
  parallel_for_each(
      nc, 1,
      [&](std::size_t c) {
        for (std::size_t i = 0; i < chunk_runs_[c].size(); ++i) {
          const Run& r = chunk_runs_[c][i];
          const std::uint32_t len = run_end(c, i) - r.begin;
          for (std::uint32_t t = 0; t < len; ++t) order[r.block + t] = r.begin + t;
        }
        // Unsorted points (a fill before the first reorder) make many runs: not kept.
        std::vector<Run>& runs = chunk_runs_[c];
        if (runs.capacity() > 2 * runs.size() + 64) std::vector<Run>(runs).swap(runs);
      },
      serial);
  // Grid blocks: every particle block and its +1 neighbours.
  ghash_.clear();
  gblock_key.clear();
  pblock_nbr.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    const Vec3i c = unpack_block(pblock_key[b]);
    for (int o = 0; o < 8; ++o) {
      const std::uint64_t k = pack_block(c[0] + (o >> 2), c[1] + ((o >> 1) & 1), c[2] + (o & 1));
      const int id = ghash_.insert(k);
      if (static_cast<std::size_t>(id) == gblock_key.size()) gblock_key.push_back(k);
      pblock_nbr[b][o] = id;
    }
  }
  const std::size_t ng = gblock_key.size();
  gblock_src.resize(ng);
  for (std::size_t g = 0; g < ng; ++g) {
    const Vec3i c = unpack_block(gblock_key[g]);
    for (int o = 0; o < 8; ++o) {
      const int sx = c[0] - (o >> 2), sy = c[1] - ((o >> 1) & 1), sz = c[2] - (o & 1);
      gblock_src[g][o] = (sx < 0 || sy < 0 || sz < 0) ? -1 : phash_.find(pack_block(sx, sy, sz));
    }
  }
  pblock_buf.resize(nb);
  gblock_nodes.resize(ng);
  parallel_for(
      ng, 64,
      [&](std::size_t b, std::size_t e) {
        std::memset(static_cast<void*>(gblock_nodes.data() + b), 0,
                    (e - b) * sizeof(gblock_nodes[0]));
      },
      serial);
}

void SparseGrid::gather(bool with_mass, bool serial) {
  parallel_for_each(
      gblock_key.size(), 4,
      [&](std::size_t g) {
        auto& nodes = gblock_nodes[g];
        for_each_buffer_node(g, [&](int dn, std::size_t src, int sn) {
          const GridNode& from = pblock_buf[src][sn];
          GridNode& d = nodes[dn];
          if (with_mass) d.m += from.m;
          d.v[0] += from.v[0];
          d.v[1] += from.v[1];
          d.v[2] += from.v[2];
        });
      },
      serial);
}

void SparseGrid::scatter_grid_to_buffers(bool serial) {
  parallel_for_each(
      pblock_key.size(), 4,
      [&](std::size_t b) {
        auto& buf = pblock_buf[b];
        for (int o = 0; o < 8; ++o) {
          const auto& nodes = gblock_nodes[pblock_nbr[b][o]];
          const int ox = (o >> 2) * 4, oy = ((o >> 1) & 1) * 4, oz = (o & 1) * 4;
          const int ix1 = ox ? 2 : 4, iy1 = oy ? 2 : 4, iz1 = oz ? 2 : 4;
          for (int i = 0; i < ix1; ++i)
            for (int j = 0; j < iy1; ++j)
              for (int k = 0; k < iz1; ++k)
                buf[pad_node(i + ox, j + oy, k + oz)] = nodes[block_node(i, j, k)];
        }
      },
      serial);
}

std::size_t SparseGrid::runs_bytes() const {
  std::size_t b = chunk_runs_.capacity() * sizeof(chunk_runs_[0]);
  for (const auto& r : chunk_runs_) b += r.capacity() * sizeof(Run);
  return b;
}

std::size_t SparseGrid::bytes() const {
  return order.capacity() * 4 + pblock_start.capacity() * 4 + pblock_key.capacity() * 8 +
         pblock_nbr.capacity() * 32 + pblock_buf.capacity() * sizeof(pblock_buf[0]) +
         gblock_key.capacity() * 8 + gblock_src.capacity() * 32 +
         gblock_nodes.capacity() * sizeof(gblock_nodes[0]) + phash_.bytes() + ghash_.bytes() +
         runs_bytes();
}

}  // namespace shellmpm

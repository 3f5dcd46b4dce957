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
  bin_points(first, xs, serial, keep_order);
  bin_grid_blocks(serial);
}

void SparseGrid::bin_for_sort(const std::vector<Vec3>& x, bool serial) {
  // The nodes go first: the order takes their place.
  std::vector<std::array<GridNode, kBlockNodes>>().swap(gblock_nodes);
  gblock_key.clear();
  gblock_src.clear();
  pblock_nbr.clear();
  ghash_.clear();
  bin_points(nullptr, x, serial, true);
}

void SparseGrid::bin_points(const std::vector<Vec3>* first, const std::vector<Vec3>& xs,
                            bool serial, bool with_order) {
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
          const std::uint64_t key = block_key(grid_coord(pos(p)));
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
  block_run_start.assign(nb + 1, 0);
  for (std::size_t c = 0; c < nc; ++c)
    for (std::size_t i = 0; i < chunk_runs_[c].size(); ++i) {
      const std::uint32_t b = chunk_runs_[c][i].block;
      pblock_start[b + 1] += run_end(c, i) - chunk_runs_[c][i].begin;
      ++block_run_start[b + 1];
    }
  for (std::size_t b = 0; b < nb; ++b) {
    pblock_start[b + 1] += pblock_start[b];
    block_run_start[b + 1] += block_run_start[b];
  }
  // Each block's runs in point order; from here a Run's `block` is its first slot in
  // order().
  block_runs.resize(block_run_start[nb]);
  std::vector<std::uint32_t> cursor(pblock_start.begin(), pblock_start.end() - 1);
  std::vector<std::uint32_t> run_cursor(block_run_start.begin(), block_run_start.end() - 1);
  for (std::size_t c = 0; c < nc; ++c)
    for (std::size_t i = 0; i < chunk_runs_[c].size(); ++i) {
      Run& r = chunk_runs_[c][i];
      const std::uint32_t len = run_end(c, i) - r.begin;
      block_runs[run_cursor[r.block]++] = {r.begin, len};
      const std::uint32_t slot = cursor[r.block];
      cursor[r.block] += len;
      r.block = slot;
    }
  num_points_ = n;
  if (with_order)
    order_.resize(n);
  else
    std::vector<std::uint32_t>().swap(order_);
  parallel_for_each(
      nc, 1,
      [&](std::size_t c) {
        if (with_order)
          for (std::size_t i = 0; i < chunk_runs_[c].size(); ++i) {
            const Run& r = chunk_runs_[c][i];
            const std::uint32_t len = run_end(c, i) - r.begin;
            for (std::uint32_t t = 0; t < len; ++t) order_[r.block + t] = r.begin + t;
          }
        // Unsorted points (a fill before the first reorder) make many runs: not kept.
        std::vector<Run>& runs = chunk_runs_[c];
        if (runs.capacity() > 2 * runs.size() + 64) std::vector<Run>(runs).swap(runs);
      },
      serial);
  // Unsorted points make many block runs too.
  if (block_runs.capacity() > 2 * block_runs.size() + 64)
    std::vector<std::array<std::uint32_t, 2>>(block_runs).swap(block_runs);
}

void SparseGrid::bin_grid_blocks(bool serial) {
  const std::size_t nb = pblock_key.size();
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
  // Columns: blocks sorted by (colour, x, y, z).
  column_blocks.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) column_blocks[b] = static_cast<std::uint32_t>(b);
  auto column_key = [&](std::uint32_t b) {
    const Vec3i c = unpack_block(pblock_key[b]);
    return std::array<int, 4>{((c[0] & 1) << 1) | (c[1] & 1), c[0], c[1], c[2]};
  };
  std::sort(column_blocks.begin(), column_blocks.end(),
            [&](std::uint32_t a, std::uint32_t b) { return column_key(a) < column_key(b); });
  column_start.clear();
  colour_columns.fill(0);
  for (std::size_t i = 0; i < nb; ++i) {
    const auto k = column_key(column_blocks[i]);
    if (i == 0 || k[1] != column_key(column_blocks[i - 1])[1] ||
        k[2] != column_key(column_blocks[i - 1])[2]) {
      column_start.push_back(static_cast<std::uint32_t>(i));
      ++colour_columns[k[0] + 1];
    }
  }
  column_start.push_back(static_cast<std::uint32_t>(nb));
  for (int c = 0; c < 4; ++c) colour_columns[c + 1] += colour_columns[c];
  if (!keep_nodes) {
    std::vector<std::array<GridNode, kBlockNodes>>().swap(gblock_nodes);
    return;
  }
  gblock_nodes.resize(ng);
  parallel_for(
      ng, 64,
      [&](std::size_t b, std::size_t e) {
        std::memset(static_cast<void*>(gblock_nodes.data() + b), 0,
                    (e - b) * sizeof(gblock_nodes[0]));
      },
      serial);
}

void SparseGrid::for_each_block_by_colour(const std::function<void(std::size_t)>& f, bool serial) {
  for (int c = 0; c < 4; ++c) {
    const std::uint32_t c0 = colour_columns[c];
    parallel_for_each(
        colour_columns[c + 1] - c0, 1,
        [&](std::size_t i) {
          for (std::uint32_t k = column_start[c0 + i]; k < column_start[c0 + i + 1]; ++k)
            f(column_blocks[k]);
        },
        serial);
  }
}

void SparseGrid::add_pad_to_grid(std::size_t b, const GridNode* pad) {
  for_each_pad_node(b, [&](int g, int bn, int pn) { add_node(gblock_nodes[g][bn], pad[pn]); });
}

void SparseGrid::copy_grid_to_pad(std::size_t b, GridNode* pad) const {
  for_each_pad_node(b, [&](int g, int bn, int pn) { pad[pn] = gblock_nodes[g][bn]; });
}

std::size_t SparseGrid::runs_bytes() const {
  std::size_t b = chunk_runs_.capacity() * sizeof(chunk_runs_[0]);
  for (const auto& r : chunk_runs_) b += r.capacity() * sizeof(Run);
  return b;
}

std::size_t SparseGrid::bytes() const {
  return order_.capacity() * 4 + pblock_start.capacity() * 4 + pblock_key.capacity() * 8 +
         block_run_start.capacity() * 4 + block_runs.capacity() * 8 + pblock_nbr.capacity() * 32 +
         (column_blocks.capacity() + column_start.capacity()) * 4 + gblock_key.capacity() * 8 +
         gblock_src.capacity() * 32 + gblock_nodes.capacity() * sizeof(gblock_nodes[0]) +
         phash_.bytes() + ghash_.bytes() + runs_bytes();
}

}  // namespace shellmpm

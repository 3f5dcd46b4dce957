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
  // (points sorted by block, as after every frame's reorder, make few runs), with each
  // chunk's distinct blocks and their point and run counts.
  const std::size_t nc = (n + kBinChunk - 1) / kBinChunk;
  if (chunks_.size() < nc) chunks_.resize(nc);
  pkeys_.resize(nc);
  auto run_end = [&](std::size_t c, std::size_t i) -> std::uint32_t {
    const auto& runs = chunks_[c].runs;
    return static_cast<std::uint32_t>(i + 1 < runs.size() ? runs[i + 1].begin
                                                          : std::min(n, (c + 1) * kBinChunk));
  };
  parallel_for_each(
      nc, 1,
      [&](std::size_t c) {
        std::vector<Run>& runs = chunks_[c].runs;
        runs.clear();
        const std::size_t e = std::min(n, (c + 1) * kBinChunk);
        for (std::size_t p = c * kBinChunk; p < e; ++p) {
          const std::uint64_t key = block_key(grid_coord(pos(p)));
          if (runs.empty() || runs.back().key != key)
            runs.push_back({key, static_cast<std::uint32_t>(p), 0});
        }
        pkeys_.begin_chunk(c);
        auto& counts = chunks_[c].counts;
        counts.clear();
        for (std::size_t i = 0; i < runs.size(); ++i) {
          const int id = pkeys_.local(c, runs[i].key);
          if (static_cast<std::size_t>(id) == counts.size()) counts.push_back({0, 0});
          counts[static_cast<std::size_t>(id)][0] += run_end(c, i) - runs[i].begin;
          ++counts[static_cast<std::size_t>(id)][1];
          runs[i].block = static_cast<std::uint32_t>(id);
        }
      },
      serial);
  // Block indices follow first appearance in point order; then the stable counting sort
  // by runs, per chunk and block: start[] from the point and run counts, each chunk's
  // first slot per block in order[] and block_runs.
  phash_.clear();
  pblock_key.clear();
  pkeys_.number(phash_, pblock_key);
  const std::size_t nb = pblock_key.size();
  pblock_start.assign(nb + 1, 0);
  block_run_start.assign(nb + 1, 0);
  for (std::size_t c = 0; c < nc; ++c) {
    const auto& counts = chunks_[c].counts;
    for (std::size_t i = 0; i < counts.size(); ++i) {
      const auto b = static_cast<std::size_t>(pkeys_.global(c, static_cast<int>(i)));
      pblock_start[b + 1] += counts[i][0];
      block_run_start[b + 1] += counts[i][1];
    }
  }
  for (std::size_t b = 0; b < nb; ++b) {
    pblock_start[b + 1] += pblock_start[b];
    block_run_start[b + 1] += block_run_start[b];
  }
  std::vector<std::uint32_t> cursor(pblock_start.begin(), pblock_start.end() - 1);
  std::vector<std::uint32_t> run_cursor(block_run_start.begin(), block_run_start.end() - 1);
  for (std::size_t c = 0; c < nc; ++c)
    for (std::size_t i = 0; i < chunks_[c].counts.size(); ++i) {
      auto& cnt = chunks_[c].counts[i];
      const auto b = static_cast<std::size_t>(pkeys_.global(c, static_cast<int>(i)));
      const std::array<std::uint32_t, 2> slots{cursor[b], run_cursor[b]};
      cursor[b] += cnt[0];
      run_cursor[b] += cnt[1];
      cnt = slots;  // from here the chunk's next slot in order[] and in block_runs
    }
  num_points_ = n;
  if (with_order)
    order_.resize(n);
  else
    std::vector<std::uint32_t>().swap(order_);
  block_runs.resize(block_run_start[nb]);
  // Each block's runs in point order.
  parallel_for_each(
      nc, 1,
      [&](std::size_t c) {
        std::vector<Run>& runs = chunks_[c].runs;
        for (std::size_t i = 0; i < runs.size(); ++i) {
          const Run& r = runs[i];
          const std::uint32_t len = run_end(c, i) - r.begin;
          auto& next = chunks_[c].counts[r.block];
          block_runs[next[1]++] = {r.begin, len};
          if (with_order)
            for (std::uint32_t t = 0; t < len; ++t) order_[next[0] + t] = r.begin + t;
          next[0] += len;
        }
        // Unsorted points (a fill before the first reorder) make many runs: not kept.
        if (runs.capacity() > 2 * runs.size() + 64) std::vector<Run>(runs).swap(runs);
      },
      serial);
  // Unsorted points make many block runs too.
  if (block_runs.capacity() > 2 * block_runs.size() + 64)
    std::vector<std::array<std::uint32_t, 2>>(block_runs).swap(block_runs);
}

void SparseGrid::bin_grid_blocks(bool serial) {
  const std::size_t nb = pblock_key.size();
  // Grid blocks: every particle block and its +1 neighbours, numbered by first appearance
  // (block by block, o by o); per chunk of blocks in parallel, then in chunk order.
  const std::size_t gc = (nb + kGridChunk - 1) / kGridChunk;
  gkeys_.resize(gc);
  pblock_nbr.resize(nb);
  parallel_for_each(
      gc, 1,
      [&](std::size_t c) {
        gkeys_.begin_chunk(c);
        for (std::size_t b = c * kGridChunk; b < std::min(nb, (c + 1) * kGridChunk); ++b) {
          const Vec3i k = unpack_block(pblock_key[b]);
          for (int o = 0; o < 8; ++o)
            pblock_nbr[b][o] =
                gkeys_.local(c, pack_block(k[0] + (o >> 2), k[1] + ((o >> 1) & 1), k[2] + (o & 1)));
        }
      },
      serial);
  ghash_.clear();
  gblock_key.clear();
  gkeys_.number(ghash_, gblock_key);
  parallel_for_each(
      gc, 1,
      [&](std::size_t c) {
        for (std::size_t b = c * kGridChunk; b < std::min(nb, (c + 1) * kGridChunk); ++b)
          for (int o = 0; o < 8; ++o) pblock_nbr[b][o] = gkeys_.global(c, pblock_nbr[b][o]);
      },
      serial);
  const std::size_t ng = gblock_key.size();
  // The particle block at key - o of each grid block: b for every b whose neighbour o it is
  // (no lookups).
  gblock_src.resize(ng);
  std::fill(gblock_src.begin(), gblock_src.end(),
            std::array<int, 8>{-1, -1, -1, -1, -1, -1, -1, -1});
  for (std::size_t b = 0; b < nb; ++b)
    for (int o = 0; o < 8; ++o) gblock_src[pblock_nbr[b][o]][o] = static_cast<int>(b);
  // Columns: blocks sorted by (colour, x, y, z), i.e. by colour and then by key (x, y, z
  // packed high to low); the four colours' sorts in parallel.
  auto colour = [](std::uint64_t key) {
    return static_cast<int>(((key >> 40) & 1) << 1 | ((key >> 20) & 1));
  };
  std::array<std::uint32_t, 5> first{};
  for (std::size_t b = 0; b < nb; ++b) ++first[colour(pblock_key[b]) + 1];
  for (int c = 0; c < 4; ++c) first[c + 1] += first[c];
  column_sort_.resize(nb);
  {
    std::array<std::uint32_t, 4> at{first[0], first[1], first[2], first[3]};
    for (std::size_t b = 0; b < nb; ++b)
      column_sort_[at[colour(pblock_key[b])]++] = {pblock_key[b], static_cast<std::uint32_t>(b)};
  }
  parallel_for_each(
      4, 1,
      [&](std::size_t c) {
        std::sort(column_sort_.begin() + first[c], column_sort_.begin() + first[c + 1]);
      },
      serial);
  column_blocks.resize(nb);
  column_start.clear();
  colour_columns.fill(0);
  for (std::size_t i = 0; i < nb; ++i) {
    column_blocks[i] = column_sort_[i].second;
    const std::uint64_t xy = column_sort_[i].first >> 20;
    if (i == 0 || xy != column_sort_[i - 1].first >> 20) {
      column_start.push_back(static_cast<std::uint32_t>(i));
      ++colour_columns[colour(column_sort_[i].first) + 1];
    }
  }
  column_start.push_back(static_cast<std::uint32_t>(nb));
  for (int c = 0; c < 4; ++c) colour_columns[c + 1] += colour_columns[c];
  if (!keep_nodes) {
    std::vector<std::array<GridNode, kBlockNodes>>().swap(gblock_nodes);
    std::vector<std::uint8_t>().swap(gblock_unset_);
    return;
  }
  // Not zeroed here: the P2G sets each block where it first reaches it, while the block is
  // in cache (a zeroing pass here wrote and the P2G read back every node once more).
  gblock_nodes.resize(ng);
  gblock_unset_.assign(ng, 1);
}

void SparseGrid::zero_unset_blocks(bool serial) {
  parallel_for(
      gblock_unset_.size(), 1024,
      [&](std::size_t b, std::size_t e) {
        for (std::size_t g = b; g < e; ++g)
          if (gblock_unset_[g]) {
            std::memset(static_cast<void*>(&gblock_nodes[g]), 0, sizeof(gblock_nodes[g]));
            gblock_unset_[g] = 0;
          }
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
  for (int o = 0; o < 8; ++o) {
    const int g = pblock_nbr[b][o];
    GridNode* nodes = gblock_nodes[g].data();
    const int ox = (o >> 2) * 4, oy = ((o >> 1) & 1) * 4, oz = (o & 1) * 4;
    const int ix1 = ox ? 2 : 4, iy1 = oy ? 2 : 4, iz1 = oz ? 2 : 4;
    if (gblock_unset_[g]) {
      // First reached: the buffer's nodes where it overlaps, 0 elsewhere.
      gblock_unset_[g] = 0;
      for (int i = 0; i < kBlockSize; ++i)
        for (int j = 0; j < kBlockSize; ++j)
          for (int k = 0; k < kBlockSize; ++k)
            nodes[block_node(i, j, k)] = (i < ix1 && j < iy1 && k < iz1)
                                             ? pad[pad_node(i + ox, j + oy, k + oz)]
                                             : GridNode{0, {0, 0, 0}};
      continue;
    }
    for (int i = 0; i < ix1; ++i)
      for (int j = 0; j < iy1; ++j)
        for (int k = 0; k < iz1; ++k)
          add_node(nodes[block_node(i, j, k)], pad[pad_node(i + ox, j + oy, k + oz)]);
  }
}

void SparseGrid::add_pad_to_grid(std::size_t b, const GridNode* pad, const PadBox& box) {
  for (int o = 0; o < 8; ++o) {
    // The box's part in this grid block: pad nodes [lo, hi) per axis, offset by oo. None:
    // all 0 here, the block is left as it is (or to zero_unset_blocks).
    int oo[3], lo[3], hi[3];
    if (!box.in_octant(o, oo, lo, hi)) continue;
    const int g = pblock_nbr[b][o];
    GridNode* nodes = gblock_nodes[g].data();
    if (gblock_unset_[g]) {
      gblock_unset_[g] = 0;
      std::memset(static_cast<void*>(nodes), 0, sizeof(gblock_nodes[g]));
      for (int i = lo[0]; i < hi[0]; ++i)
        for (int j = lo[1]; j < hi[1]; ++j)
          for (int k = lo[2]; k < hi[2]; ++k)
            nodes[block_node(i - oo[0], j - oo[1], k - oo[2])] = pad[pad_node(i, j, k)];
      continue;
    }
    for (int i = lo[0]; i < hi[0]; ++i)
      for (int j = lo[1]; j < hi[1]; ++j)
        for (int k = lo[2]; k < hi[2]; ++k)
          add_node(nodes[block_node(i - oo[0], j - oo[1], k - oo[2])], pad[pad_node(i, j, k)]);
  }
}

void SparseGrid::zero_pad_box(GridNode* pad, const PadBox& box) {
  if (box.empty()) return;
  const auto run = static_cast<std::size_t>(box.hi[2] - box.lo[2]) * sizeof(GridNode);
  for (int i = box.lo[0]; i < box.hi[0]; ++i)
    for (int j = box.lo[1]; j < box.hi[1]; ++j)
      std::memset(static_cast<void*>(pad + pad_node(i, j, box.lo[2])), 0, run);
}

void SparseGrid::copy_grid_to_pad(std::size_t b, GridNode* pad) const {
  for_each_pad_node(b, [&](int g, int bn, int pn) { pad[pn] = gblock_nodes[g][bn]; });
}

std::size_t SparseGrid::runs_bytes() const {
  std::size_t b = chunks_.capacity() * sizeof(chunks_[0]) + pkeys_.bytes() + gkeys_.bytes();
  for (const auto& ch : chunks_)
    b += ch.runs.capacity() * sizeof(Run) + ch.counts.capacity() * sizeof(ch.counts[0]);
  return b;
}

std::size_t SparseGrid::bytes() const {
  return order_.capacity() * 4 + pblock_start.capacity() * 4 + pblock_key.capacity() * 8 +
         block_run_start.capacity() * 4 + block_runs.capacity() * 8 + pblock_nbr.capacity() * 32 +
         (column_blocks.capacity() + column_start.capacity()) * 4 + column_sort_.capacity() * 16 +
         gblock_key.capacity() * 8 + gblock_src.capacity() * 32 +
         gblock_nodes.capacity() * sizeof(gblock_nodes[0]) + gblock_unset_.capacity() +
         phash_.bytes() + ghash_.bytes() + runs_bytes();
}

}  // namespace shellmpm

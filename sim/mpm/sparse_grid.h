// A sparse grid of 4x4x4-node blocks that exist only around particles.
//
// Determinism without atomics (house style 7): particles are binned by the block of
// their lowest stencil node ("particle block"), whose stencils cover a padded 6x6x6 node
// region. Blocks are summed by colour, which does not depend on how threads are
// scheduled, so results are bit-identical for any thread count: columns of particle
// blocks along z whose x and y have the same parities are two blocks apart and their
// regions do not overlap; the four colours run one after the other, the columns of one
// colour in parallel, each block of a column in turn scattering into a thread's own padded
// buffer (its bulk particles, then its shell points) and adding it straight into the grid
// blocks. (Per-body grids with buffers of their own, e.g. the shells' fold classes, sum
// them per grid block with for_each_buffer_node, always in the same order.)
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "sim/core/block_hash.h"
#include "sim/core/check.h"
#include "sim/core/chunked_keys.h"
#include "sim/core/types.h"

namespace shellmpm {

/// One grid node: mass and momentum during P2G, mass and velocity after the update.
struct GridNode {
  Real m;
  Real v[3];
};

constexpr int kBlockSize = 4;    ///< nodes per block edge
constexpr int kBlockNodes = 64;  ///< nodes per block
constexpr int kPadSize = 6;      ///< padded particle-block buffer edge
constexpr int kPadNodes = 216;   ///< nodes in a padded buffer

/// Node index within a 4^3 block (z fastest).
inline int block_node(int i, int j, int k) {
  return (i * kBlockSize + j) * kBlockSize + k;
}
/// Node index within a padded 6^3 buffer (z fastest).
inline int pad_node(int i, int j, int k) {
  return (i * kPadSize + j) * kPadSize + k;
}

/// Nodes of a padded buffer in [lo, hi) on each axis: the union of the stencils of the
/// points a block scattered (empty until one is added).
struct PadBox {
  int lo[3] = {kPadSize, kPadSize, kPadSize}, hi[3] = {0, 0, 0};
  /// Adds the stencil with lowest node (lx, ly, lz) in the buffer.
  void add_stencil(int lx, int ly, int lz) {
    const int l[3] = {lx, ly, lz};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], l[a]);
      hi[a] = std::max(hi[a], l[a] + 3);
    }
  }
  bool empty() const { return lo[0] >= hi[0]; }
  /// Its part in octant o of the buffer (grid block pblock_nbr[b][o], whose first node is
  /// the buffer's node oo): nodes [lo, hi) per axis; false where there is none.
  bool in_octant(int o, int (&oo)[3], int (&part_lo)[3], int (&part_hi)[3]) const {
    bool any = true;
    for (int a = 0; a < 3; ++a) {
      oo[a] = ((o >> (2 - a)) & 1) * kBlockSize;
      part_lo[a] = std::max(lo[a], oo[a]);
      part_hi[a] = std::min(hi[a], oo[a] ? kPadSize : kBlockSize);
      any = any && part_lo[a] < part_hi[a];
    }
    return any;
  }
};

class SparseGrid {
 public:
  /// dx: spacing [m]; origin: world position of node (0,0,0) [m].
  void setup(double dx, const Vec3d& origin);

  /// Bins particle positions into particle blocks, sorts an index list by block and
  /// allocates the grid blocks they touch. Their nodes are set by the first
  /// add_pad_to_grid that reaches them (the rest of the block zeroed) and by
  /// zero_unset_blocks (particles_to_grid calls it last): read them only after those.
  void bin(const std::vector<Vec3>& x, bool serial = false) { bin(nullptr, x, serial); }
  /// Bins the concatenation of `first` (may be null) and `x`: index i < first->size()
  /// is first[i], the others x[i - first->size()].
  void bin(const std::vector<Vec3>* first, const std::vector<Vec3>& x, bool serial = false);

  double dx() const { return dx_; }
  const Vec3d& origin() const { return origin_; }
  /// Grid coordinates (position - origin) / dx of a world position.
  Vec3 grid_coord(const Vec3& p) const {
    return Vec3(static_cast<Real>((p[0] - origin_[0]) * inv_dx_),
                static_cast<Real>((p[1] - origin_[1]) * inv_dx_),
                static_cast<Real>((p[2] - origin_[2]) * inv_dx_));
  }
  /// Packed key of the particle block of a point at grid coordinates g (the block of its
  /// lowest stencil node); throws for a point off the grid.
  std::uint64_t block_key(const Vec3& g) const {
    const int bx = static_cast<int>(std::floor(g[0] - Real(0.5))) >> 2;
    const int by = static_cast<int>(std::floor(g[1] - Real(0.5))) >> 2;
    const int bz = static_cast<int>(std::floor(g[2] - Real(0.5))) >> 2;
    SHELLMPM_CHECK(
        bx >= 0 && by >= 0 && bz >= 0 && bx < (1 << 19) && by < (1 << 19) && bz < (1 << 19),
        << "a point at grid coordinates " << g.transpose() << " is off the grid");
    return pack_block(bx, by, bz);
  }
  /// World position of a node.
  Vec3d node_position(const Vec3i& n) const { return origin_ + dx_ * n.cast<double>(); }

  std::size_t num_particle_blocks() const { return pblock_key.size(); }
  std::size_t num_grid_blocks() const { return gblock_key.size(); }
  /// Bytes held by the grid's arrays.
  std::size_t bytes() const;

  /// Whether bin() allocates and zeroes the grid blocks' nodes: off for a grid that only
  /// bins (the per-shell fields keep their own node arrays).
  bool keep_nodes = true;
  /// Whether bin() fills order(): off where only the bulk transfers and the collider
  /// reach read the binning (they walk block_runs), saving 4 bytes per point.
  bool keep_order = true;
  /// Point indices sorted by particle block (kept only with keep_order).
  const std::vector<std::uint32_t>& order() const {
    SHELLMPM_CHECK(order_.size() == num_points_, << "the grid was binned without its order");
    return order_;
  }
  /// Bins x and fills order() only, for sorting the points by block: no grid blocks
  /// (num_grid_blocks() is 0 until the next bin, their nodes are freed).
  void bin_for_sort(const std::vector<Vec3>& x, bool serial = false);
  /// Frees order() when keep_order is off (after bin_for_sort).
  void release_order() {
    if (!keep_order) std::vector<std::uint32_t>().swap(order_);
  }

  // Particle blocks (binned particles).
  std::vector<std::uint32_t> pblock_start;  ///< order()[pblock_start[b] .. pblock_start[b+1])
  /// Block b's points as runs of consecutive indices in ascending order (the order of
  /// its slice of order()): block_runs[block_run_start[b] .. block_run_start[b+1]), each
  /// {first index, count}.
  std::vector<std::uint32_t> block_run_start;
  std::vector<std::array<std::uint32_t, 2>> block_runs;
  std::vector<std::uint64_t> pblock_key;       ///< packed block coordinate
  std::vector<std::array<int, 8>> pblock_nbr;  ///< grid block at key + (ox,oy,oz), o = 4ox+2oy+oz
  /// Particle blocks in columns along z (same x and y), each column ascending in z; the
  /// columns grouped by colour (x&1)<<1 | (y&1): column i is column_blocks[column_start[i]
  /// .. column_start[i+1]), the columns of colour c are colour_columns[c] .. [c+1].
  std::vector<std::uint32_t> column_blocks, column_start;
  std::array<std::uint32_t, 5> colour_columns{};
  // Grid blocks.
  std::vector<std::uint64_t> gblock_key;
  std::vector<std::array<int, 8>> gblock_src;  ///< particle block at key - o, or -1
  std::vector<std::array<GridNode, kBlockNodes>> gblock_nodes;

  /// Calls f(node, index) for every node of grid block b that has mass; index is the
  /// node's global grid index.
  template <class F>
  void for_each_massive_node(std::size_t b, F&& f) {
    const Vec3i c = unpack_block(gblock_key[b]) * kBlockSize;
    auto& nodes = gblock_nodes[b];
    for (int i = 0; i < kBlockSize; ++i)
      for (int j = 0; j < kBlockSize; ++j)
        for (int k = 0; k < kBlockSize; ++k) {
          GridNode& nd = nodes[block_node(i, j, k)];
          if (nd.m > 0) f(nd, Vec3i(c[0] + i, c[1] + j, c[2] + k));
        }
  }

  /// Calls f(i) for every point i >= first of particle block b, ascending.
  template <class F>
  void for_each_point(std::size_t b, F&& f, std::uint32_t first = 0) const {
    for (std::uint32_t r = block_run_start[b]; r < block_run_start[b + 1]; ++r) {
      const std::uint32_t e = block_runs[r][0] + block_runs[r][1];
      for (std::uint32_t i = std::max(block_runs[r][0], first); i < e; ++i) f(i);
    }
  }

  /// Index of the grid block with packed key `key`, or -1.
  int find_grid_block(std::uint64_t key) const { return ghash_.find(key); }

  /// For grid block g, calls f(block_node_index, particle_block, pad_node_index) for each
  /// padded-buffer node that overlaps it, in the fixed order the gathers use.
  template <class F>
  void for_each_buffer_node(std::size_t g, F&& f) const {
    for (int o = 0; o < 8; ++o) {
      const int src = gblock_src[g][o];
      if (src < 0) continue;
      const int ox = (o >> 2) * 4, oy = ((o >> 1) & 1) * 4, oz = (o & 1) * 4;
      const int ix1 = ox ? 2 : 4, iy1 = oy ? 2 : 4, iz1 = oz ? 2 : 4;
      for (int i = 0; i < ix1; ++i)
        for (int j = 0; j < iy1; ++j)
          for (int k = 0; k < iz1; ++k)
            f(block_node(i, j, k), static_cast<std::size_t>(src), pad_node(i + ox, j + oy, k + oz));
    }
  }

  /// Calls f(b) for every particle block b: colour by colour, the columns of one colour in
  /// parallel, the blocks of a column in z order (columns of one colour cover disjoint
  /// nodes, so each block may add to the grid directly).
  void for_each_block_by_colour(const std::function<void(std::size_t)>& f, bool serial = false);
  /// Grid block and node index of node (px, py, pz) of particle block b's padded region.
  std::pair<int, int> pad_to_grid(std::size_t b, int px, int py, int pz) const {
    const int o = ((px >> 2) << 2) | ((py >> 2) << 1) | (pz >> 2);
    return {pblock_nbr[b][o], block_node(px & 3, py & 3, pz & 3)};
  }
  /// Adds a padded buffer of particle block b into the grid nodes it overlaps (a grid
  /// block not yet reached since the last bin takes the buffer's nodes, 0 elsewhere).
  void add_pad_to_grid(std::size_t b, const GridNode* pad);
  /// The same where the buffer is 0 outside box: only the nodes in it are added (adding
  /// +0 changes no node: the sums never hold -0).
  void add_pad_to_grid(std::size_t b, const GridNode* pad, const PadBox& box);
  /// Zeroes the nodes of a padded buffer in box.
  static void zero_pad_box(GridNode* pad, const PadBox& box);
  /// Zeroes the grid blocks no add_pad_to_grid has reached since the last bin.
  void zero_unset_blocks(bool serial = false);
  /// Copies the grid nodes that particle block b's padded region overlaps into pad.
  void copy_grid_to_pad(std::size_t b, GridNode* pad) const;
  /// Calls f(grid block, node in it, node of the padded region) for every node of particle
  /// block b's padded region.
  template <class F>
  void for_each_pad_node(std::size_t b, F&& f) const {
    for (int o = 0; o < 8; ++o) {
      const int g = pblock_nbr[b][o];
      const int ox = (o >> 2) * 4, oy = ((o >> 1) & 1) * 4, oz = (o & 1) * 4;
      const int ix1 = ox ? 2 : 4, iy1 = oy ? 2 : 4, iz1 = oz ? 2 : 4;
      for (int i = 0; i < ix1; ++i)
        for (int j = 0; j < iy1; ++j)
          for (int k = 0; k < iz1; ++k) f(g, block_node(i, j, k), pad_node(i + ox, j + oy, k + oz));
    }
  }

 private:
  /// d += s.
  static void add_node(GridNode& d, const GridNode& s) {
    d.m += s.m;
    d.v[0] += s.v[0];
    d.v[1] += s.v[1];
    d.v[2] += s.v[2];
  }
  void bin_points(const std::vector<Vec3>* first, const std::vector<Vec3>& x, bool serial,
                  bool with_order);
  void bin_grid_blocks(bool serial);
  /// Per grid block, 1 until its nodes are set after a bin (the colour order makes the
  /// blocks one colour's particle blocks reach disjoint, so no two threads share a byte's
  /// block).
  std::vector<std::uint8_t> gblock_unset_;
  std::vector<std::uint32_t> order_;
  std::size_t num_points_ = 0;
  double dx_ = 1.0, inv_dx_ = 1.0;
  Vec3d origin_{0, 0, 0};
  BlockHash phash_, ghash_;
  /// A run of consecutive points in one particle block: its key, first point, and its
  /// block's index among its chunk's distinct blocks.
  struct Run {
    std::uint64_t key;
    std::uint32_t begin, block;
  };
  static constexpr std::size_t kBinChunk = 16384;  ///< points per binning chunk
  static constexpr std::size_t kGridChunk = 256;   ///< particle blocks per numbering chunk
  /// A binning chunk's runs and, per distinct block (chunk order), its point and run
  /// counts, then its next slots in order() and block_runs; kept between calls.
  struct Chunk {
    std::vector<Run> runs;
    std::vector<std::array<std::uint32_t, 2>> counts;
  };
  std::vector<Chunk> chunks_;
  ChunkedKeys pkeys_, gkeys_;  ///< particle blocks (per point chunk), grid blocks
  std::vector<std::pair<std::uint64_t, std::uint32_t>> column_sort_;  ///< (key, block)
  std::size_t runs_bytes() const;
};

}  // namespace shellmpm

// Geometric queries on triangle meshes (the integrity monitor, the shell guard): closest points,
// segment-triangle intersection and a uniform grid of triangles for neighbour search.
// Double precision throughout: the monitor judges the float state, it must not add
// round-off of its own.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "sim/core/block_hash.h"
#include "sim/core/chunked_keys.h"
#include "sim/core/types.h"

namespace shellmpm {

/// Closest point on triangle (a, b, c) to p (Ericson, "Real-Time Collision Detection",
/// sec. 5.1.5): returns the barycentric coordinates (u, v, w) of the closest point,
/// u a + v b + w c, all in [0, 1] and summing to 1.
Vec3d closest_point_barycentric(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

/// Closest points of the segments [p0, p1] and [q0, q1] (Ericson sec. 5.1.9): returns
/// (s, t) in [0, 1]^2 with p0 + s (p1 - p0) and q0 + t (q1 - q0) closest. Parallel
/// segments give one of the closest pairs; degenerate segments are points.
Eigen::Vector2d closest_segment_params(const Vec3d& p0, const Vec3d& p1, const Vec3d& q0,
                                       const Vec3d& q1);

/// Whether the segment [p, q] crosses the triangle (a, b, c) (Moller-Trumbore, both end
/// points included); segments in the triangle's plane count as not crossing.
bool segment_crosses_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& a, const Vec3d& b,
                              const Vec3d& c);

/// Triangles binned into cubic cells of side `cell`, each triangle in every cell that
/// its bounding box grown by `pad` overlaps. Deterministic (a stable counting sort by
/// cell); a cell's listings are found by hash, not by search.
class TriangleGrid {
 public:
  void build(const std::vector<Vec3d>& pos, const std::vector<Eigen::Vector3i>& tris, double cell,
             double pad, bool serial = false);
  /// The same for boxes (lo x, y, z, hi x, y, z) in place of the triangles' boxes.
  void build(const std::vector<std::array<double, 6>>& boxes, double cell, double pad,
             bool serial = false);
  /// Triangles listed in the cell that holds p (a superset of those within `pad` of p).
  void query(const Vec3d& p, std::vector<int>& out) const;
  /// Triangles listed in any cell that the box [lo, hi] overlaps, sorted, no repeats.
  void query_box(const Vec3d& lo, const Vec3d& hi, std::vector<int>& out) const;
  /// Calls fn(triangle) for every listing in the cells that the box [lo, hi] overlaps,
  /// in cell order; a triangle listed in several of them is visited once per cell.
  template <class Fn>
  void for_each_in_box(const Vec3d& lo, const Vec3d& hi, Fn&& fn) const {
    if (!lo.allFinite() || !hi.allFinite()) return;
    const Vec3i c0 = cell_of(lo), c1 = cell_of(hi);
    for (int i = c0[0]; i <= c1[0]; ++i)
      for (int j = c0[1]; j <= c1[1]; ++j)
        for (int k = c0[2]; k <= c1[2]; ++k) {
          const int c = cells_.find(key(Vec3i(i, j, k)));
          if (c < 0) continue;
          const std::size_t e = cell_start_[static_cast<std::size_t>(c) + 1];
          for (std::size_t l = cell_start_[static_cast<std::size_t>(c)]; l < e; ++l) fn(tri_[l]);
        }
  }
  bool empty() const { return tri_.empty(); }
  /// Cells that list something, numbered 0 .. num_cells() - 1.
  std::size_t num_cells() const { return cell_key_.size(); }
  /// Cell c's key (key() of its coordinates).
  std::uint64_t cell_key(std::size_t c) const { return cell_key_[c]; }
  /// Cell c's triangles, ascending: [first, last).
  const int* cell_begin(std::size_t c) const { return tri_.data() + cell_start_[c]; }
  const int* cell_end(std::size_t c) const { return tri_.data() + cell_start_[c + 1]; }
  /// The cell that holds p: floor(p / cell) per axis. A triangle with bounding box
  /// [lo, hi] is listed in the cells from cell_of(lo - pad) to cell_of(hi + pad).
  Vec3i cell_of(const Vec3d& p) const;
  /// The key of the cell with coordinates c.
  std::uint64_t key(const Vec3i& c) const;

 private:
  /// build() for n items, box_of(i, lo, hi) giving item i's box.
  template <class BoxOf>
  void build_impl(std::size_t n, const BoxOf& box_of, double cell, double pad, bool serial);
  double inv_cell_ = 1;
  /// The triangles tri_[cell_start_[c] .. cell_start_[c + 1]) in the cell numbered c by
  /// cells_ (cells by first appearance in triangle order), ascending.
  std::vector<int> tri_;
  std::vector<std::size_t> cell_start_;
  std::vector<std::uint64_t> cell_key_;  ///< per cell number, its key
  BlockHash cells_;
  // build's work space, kept: the (cell key, triangle) pairs in triangle order, each
  // pair's cell among its chunk's, per chunk its cells' counts (then next slots).
  static constexpr std::size_t kChunk = 16384;
  std::vector<std::pair<std::uint64_t, int>> pairs_;
  std::vector<int> pair_cell_;
  ChunkedKeys chunk_keys_;
  std::vector<std::vector<std::size_t>> chunk_slots_;
};

}  // namespace shellmpm

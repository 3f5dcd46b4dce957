// Geometric queries on triangle meshes for the integrity monitor: closest points,
// segment-triangle intersection and a uniform grid of triangles for neighbour search.
// Double precision throughout: the monitor judges the float state, it must not add
// round-off of its own.
#pragma once
#include <cstdint>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

/// Closest point on triangle (a, b, c) to p (Ericson, "Real-Time Collision Detection",
/// sec. 5.1.5): returns the barycentric coordinates (u, v, w) of the closest point,
/// u a + v b + w c, all in [0, 1] and summing to 1.
Vec3d closest_point_barycentric(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

/// Whether the segment [p, q] crosses the triangle (a, b, c) (Moller-Trumbore, both end
/// points included); segments in the triangle's plane count as not crossing.
bool segment_crosses_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& a, const Vec3d& b,
                              const Vec3d& c);

/// Triangles binned into cubic cells of side `cell`, each triangle in every cell that
/// its bounding box grown by `pad` overlaps. Deterministic (sorted pairs).
class TriangleGrid {
 public:
  void build(const std::vector<Vec3d>& pos, const std::vector<Eigen::Vector3i>& tris, double cell,
             double pad);
  /// Triangles listed in the cell that holds p (a superset of those within `pad` of p).
  void query(const Vec3d& p, std::vector<int>& out) const;
  /// Triangles listed in any cell that the box [lo, hi] overlaps, sorted, no repeats.
  void query_box(const Vec3d& lo, const Vec3d& hi, std::vector<int>& out) const;
  bool empty() const { return keys_.empty(); }

 private:
  std::uint64_t key(const Vec3i& c) const;
  Vec3i cell_of(const Vec3d& p) const;
  double inv_cell_ = 1;
  std::vector<std::uint64_t> keys_;  ///< sorted cell keys, one per (cell, triangle) pair
  std::vector<int> tri_;             ///< triangle of each pair
};

}  // namespace shellmpm

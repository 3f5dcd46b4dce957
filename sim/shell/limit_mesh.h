// The mesh a shell writes: its Loop limit surface sampled on the control triangles,
// each refined into 4^levels sub-triangles. Vertex count and order are fixed at setup,
// so every frame has the same layout; positions and normals are sparse linear maps of
// the control points, precomputed once.
#pragma once
#include <vector>

#include "sim/core/types.h"
#include "sim/shell/loop_basis.h"

namespace shellmpm {

/// UV seams: a sample point on a corner or an edge of the control mesh is one output
/// vertex for all the faces around it that give it the same texture coordinates (the
/// same `uv_triangles` entries), and one per distinct set otherwise; so the output is
/// split along UV seams, and the copies of a point share one row (position, normal,
/// velocity) and differ only in their UV. Without UVs nothing is split.
class LimitMesh {
 public:
  /// @param uvs          texture coordinates (may be empty), indexed by `uv_triangles`
  /// @param uv_triangles per control triangle, the `uvs` index of each corner; empty
  ///                     exactly when `uvs` is. UVs are interpolated linearly in each face.
  LimitMesh(const LoopBasis& basis, const std::vector<Eigen::Vector3i>& triangles,
            const std::vector<Eigen::Vector2d>& uvs,
            const std::vector<Eigen::Vector3i>& uv_triangles, int levels);
  /// uvs: per control vertex (may be empty), i.e. uv_triangles == triangles.
  LimitMesh(const LoopBasis& basis, const std::vector<Eigen::Vector3i>& triangles,
            const std::vector<Eigen::Vector2d>& uvs, int levels);

  std::size_t num_vertices() const { return vertex_row_.size(); }
  /// 4^levels triangles per control triangle, in control-triangle order, each oriented
  /// as its control triangle (levels 0: triangle t is control triangle t, corners in order).
  const std::vector<Eigen::Vector3i>& triangles() const { return tris_; }
  /// One UV per output vertex; empty without UVs.
  const std::vector<Eigen::Vector2d>& uvs() const { return uvs_; }
  /// Output vertex r as a combination of control points: its position is
  /// sum_k row_weights(r)[k] x[row_points(r)[k]] (the weights sum to 1).
  const std::vector<int>& row_points(std::size_t r) const { return rows_[vertex_row_[r]].ctrl; }
  const std::vector<Real>& row_weights(std::size_t r) const { return rows_[vertex_row_[r]].n; }
  /// Limit positions and unit normals of the output vertices for control points x.
  void evaluate(const Vec3* x, std::vector<Vec3>& pos, std::vector<Vec3>& normal) const;
  /// Velocities of the output vertices [m/s] for control-point velocities v [m/s]: the
  /// position map applied to v, vel[r] = sum_k row_weights(r)[k] v[row_points(r)[k]],
  /// so it is the exact time derivative of evaluate()'s positions. Same count and order.
  void evaluate_velocity(const Vec3* v, std::vector<Vec3>& vel) const;

 private:
  struct Row {
    std::vector<int> ctrl;
    std::vector<Real> n, d1, d2;
  };
  std::vector<Row> rows_;        ///< one per distinct sample point of the surface
  std::vector<int> vertex_row_;  ///< per output vertex, its row (copies at UV seams share one)
  std::vector<Eigen::Vector3i> tris_;
  std::vector<Eigen::Vector2d> uvs_;
};

}  // namespace shellmpm

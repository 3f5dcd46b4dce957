// A triangle control mesh for a shell, as read from a file or built procedurally.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

/// The control mesh (one control point per position: the simulation needs its
/// connectivity) and, beside it, the per-corner texture coordinates the output meshes
/// keep (split at UV seams; see LimitMesh).
struct ShellMesh {
  std::vector<Vec3d> vertices;             ///< control points, rest pose [m]
  std::vector<Eigen::Vector3i> triangles;  ///< counter-clockwise seen from +normal
  /// Texture coordinates, indexed per triangle corner by `uv_triangles`; empty when the
  /// input has none. Several entries may belong to one control point: a UV seam.
  std::vector<Eigen::Vector2d> uvs;
  /// Per triangle, the `uvs` index of each corner (same order as `triangles`); empty
  /// exactly when `uvs` is. A mesh without seams has uv_triangles == triangles.
  std::vector<Eigen::Vector3i> uv_triangles;
  std::map<std::string, std::vector<int>> groups;  ///< named vertex groups (sorted indices)
};

}  // namespace shellmpm

// A triangle control mesh for a shell, as read from a file or built procedurally.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

struct ShellMesh {
  std::vector<Vec3d> vertices;                     ///< control points, rest pose [m]
  std::vector<Eigen::Vector3i> triangles;          ///< counter-clockwise seen from +normal
  std::vector<Eigen::Vector2d> uvs;                ///< per vertex; empty when the input has none
  std::map<std::string, std::vector<int>> groups;  ///< named vertex groups (sorted indices)
};

}  // namespace shellmpm

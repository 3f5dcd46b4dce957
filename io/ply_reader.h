// Reading back the binary PLY caches a run writes (particles.####.ply, shell meshes),
// fast and strictly: anything but little-endian binary with float x, y, z is refused.
#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

namespace shellmpm {

/// A float position or direction, as the caches store them (the same type as the preview
/// renderer's Vec3f).
using Vec3f = Eigen::Vector3f;

struct PlyMesh {
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;              ///< empty unless the file has nx, ny, nz
  std::vector<Eigen::Vector2f> uvs;        ///< empty unless the file has float s, t
  std::vector<Vec3f> velocities;           ///< empty unless the file has float vx, vy, vz
  std::vector<Eigen::Vector3i> triangles;  ///< empty for point clouds
};

/// Reads vertices (x, y, z and, when present, nx, ny, nz; s, t; vx, vy, vz) and triangle
/// faces.
/// @throws std::runtime_error whose message starts with `path`: missing or unreadable file,
///         not PLY, not binary little-endian, no float x/y/z, a face that is not a triangle or
///         indexes past the vertices, a non-finite coordinate, or a truncated body.
PlyMesh read_ply(const std::string& path);

}  // namespace shellmpm

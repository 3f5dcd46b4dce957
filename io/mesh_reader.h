// Triangle meshes from files (OBJ, PLY, STL, glTF, FBX, ... anything assimp reads),
// for mesh sources and mesh colliders.
#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

#include "io/user_error.h"
#include "sim/core/types.h"

struct aiScene;
namespace Assimp {
class Importer;
}  // namespace Assimp

namespace shellmpm {

/// An indexed triangle mesh in world units [m].
struct TriMesh {
  std::vector<Vec3d> vertices;
  std::vector<Eigen::Vector3i> triangles;  ///< indices into `vertices`
  std::vector<Eigen::Vector2d> uvs;        ///< per vertex (channel 0); empty if any part lacks UVs
};

/// Reads every mesh of a file into one TriMesh.
///
/// - Polygons are triangulated (aiProcess_Triangulate); points and lines are dropped.
/// - Vertices are joined only as assimp's aiProcess_JoinIdenticalVertices does: within
///   one assimp mesh, vertices equal in *all* attributes (position, normal, UV, ...)
///   become one. Vertices that share a position but differ in a normal or UV (hard
///   edges, UV seams, STL facets with normals) stay separate; meshes are not welded
///   to each other. The order follows the file's first occurrences, but is not
///   guaranteed to match the file's vertex order.
/// - All meshes in the file are merged, each placed by its node's accumulated
///   transform (a mesh instanced by several nodes appears once per node).
/// - `uvs` holds texture channel 0 when every merged mesh has it, else it is empty.
///
/// @param path  the mesh file
/// @param where the location that named the file, for messages, in UserError's
///              "file:line: key" form, e.g. "scene.yaml:14: colliders[0].shape.path"
///              ("file: key" and a bare "file" are accepted too).
/// @throws UserError at `where`, naming `path`, when the file is missing or unreadable
///         (with assimp's error string), has no triangles, or has non-finite coordinates.
TriMesh read_mesh(const std::string& path, const std::string& where);

namespace detail {
/// A UserError at `where` ("file:line: key", "file: key" or "file"; see read_mesh).
UserError user_error_at(const std::string& where, const std::string& message);
/// Reads `path` with `importer`: triangulated, identical vertices joined, points and lines
/// dropped. @throws UserError naming `where` and the path when it cannot be read.
const aiScene* import_triangles(Assimp::Importer& importer, const std::string& path,
                                const std::string& where);
}  // namespace detail

}  // namespace shellmpm

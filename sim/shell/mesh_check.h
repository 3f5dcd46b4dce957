// Validation of a shell control mesh before it is handed to LoopBasis.
#pragma once

#include <string>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {

/// What is wrong with a control mesh. All kinds are errors for simulation.
enum class MeshProblemKind {
  NonManifoldEdge,          ///< an edge shared by more than two faces
  NonManifoldVertex,        ///< the faces around a vertex form more than one fan (bow tie)
  DuplicateVertex,          ///< two or more vertices at exactly the same position
  ZeroAreaFace,             ///< a face with (numerically) zero area
  InconsistentOrientation,  ///< two faces traverse a shared edge in the same direction
  DegenerateIndex,          ///< a face index out of range, or repeated within the face
  IsolatedVertex,           ///< a vertex used by no (valid) face
};

/// Name of a kind, e.g. "non-manifold edge".
const char* to_string(MeshProblemKind kind);

struct MeshProblem {
  MeshProblemKind kind;
  std::vector<int> faces;     ///< faces involved (may be empty)
  std::vector<int> vertices;  ///< vertices involved (may be empty)
  std::string message;        ///< one line naming the kind, faces and vertices
};

/// Checks a triangle control mesh (counter-clockwise faces) for everything LoopBasis
/// cannot simulate. Returns an empty list for a good mesh. Faces with a DegenerateIndex
/// are left out of the other checks. A face is ZeroAreaFace when
/// |(b - a) x (c - a)| <= 1e-12 * (longest edge)^2 (or all its edges have zero length).
/// Problems come in a fixed order: by kind (as listed in the enum), then by index.
std::vector<MeshProblem> check_shell_mesh(const std::vector<Vec3d>& vertices,
                                          const std::vector<Eigen::Vector3i>& tris);

}  // namespace shellmpm

// Per-frame shell mesh caches (DESIGN.md, output conventions): one file per frame,
// the same vertex count and order every frame, normals and UVs carried through,
// written to a temporary name and renamed.
//
// Format decisions. All three formats are written by this file, not by assimp's
// Exporter: checked with assimp 5.2.5, the "obj" exporter reorders vertices (it
// numbers them in face-traversal order) and shares normals, and the "glb2" exporter
// enforces aiProcess_JoinIdenticalVertices, which merges coincident vertices and
// reorders them; only "plyb" keeps the order, but copying the scene costs time.
// The writers below emit exactly `num_vertices` vertices in the given order:
//   - Ply: binary little-endian PLY. vertex: float x y z nx ny nz [s t] [vx vy vz];
//     face: list uchar int vertex_indices. Comments carry name, frame and time (and
//     "up_axis z" when written Z-up).
//     Velocities use the particle cache's names (io/particle_cache.h): PLY properties
//     are scalars (Blender 4.1+ imports each extra one as a float attribute); a
//     wrangle joins them into Houdini's vector `v` (v@v = set(f@vx, f@vy, f@vz)).
//   - Obj: "v x y z", "vn", "vt" lines, one of each per vertex, so every face
//     corner is "i/i/i" (or "i//i" without UVs); shortest round-trip float text.
//     OBJ has no per-vertex attributes: velocities are not written.
//   - Glb: glTF 2.0 binary, one mesh with one triangle primitive: POSITION, NORMAL,
//     TEXCOORD_0, _VELOCITY (float; the last an application-specific attribute, glTF
//     2.0 section 3.7.2.1) and UNSIGNED_INT indices. glTF puts the UV origin at the
//     top-left, so TEXCOORD_0 = (u, 1 - v) (assimp and Blender flip it back).
//     Frame and time are in the scene's "extras".
// Every format stores 32-bit floats (also in a SHELLMPM_DOUBLE build).
// Note for readers: assimp's OBJ importer (without aiProcess_JoinIdenticalVertices)
// emits one vertex per face corner; the file itself holds the vertices in order.
#pragma once
#include <Eigen/Core>
#include <cstddef>
#include <string>

#include "sim/core/types.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// "ply" | "obj" | "glb" (lower case). Throws std::invalid_argument otherwise.
MeshFormat parse_mesh_format(const std::string& name);

/// The file extension of `format`, without the dot ("ply", "obj", "glb").
const char* mesh_format_extension(MeshFormat format);

/// One frame of a shell mesh. Views, not owned; they must outlive the write call.
struct MeshFrame {
  const Vec3* positions = nullptr;  ///< num_vertices positions [m]
  std::size_t num_vertices = 0;
  /// num_vertices normals, or null: then area-weighted vertex normals are computed
  /// from the triangles (a vertex on no triangle gets (0, 0, 0)). Written normalized.
  const Vec3* normals = nullptr;
  const Eigen::Vector2d* uvs = nullptr;  ///< num_vertices UVs (origin bottom-left), or null
  /// num_vertices velocities [m/s], or null (none written). PLY vx vy vz, GLB _VELOCITY;
  /// OBJ ignores them.
  const Vec3* velocities = nullptr;
  const Eigen::Vector3i* triangles = nullptr;  ///< counter-clockwise seen from +normal
  std::size_t num_triangles = 0;
  int frame = 0;      ///< frame number, recorded in the file
  double time = 0.0;  ///< simulation time [s], recorded in the file
  std::string name;   ///< object name (OBJ "o", glTF node and mesh name)
  /// The axes to write in (output.up_axis): positions, normals and velocities are turned
  /// by to_output_axes (sim/scene/output_axes.h) after rounding to float, so the file is
  /// an exact rotation of the Y-up one. GLB ignores it (mesh_file_up_axis,
  /// sim/scene/output_axes.h).
  UpAxis up_axis = UpAxis::Y;
};

/// Writes `mesh` to `path` atomically (io/atomic_file.h) in `format`, with exactly
/// `mesh.num_vertices` vertices in the given order and the triangles as given.
/// Throws InvariantError (a caller bug) when there are no vertices or no triangles,
/// `positions` or `triangles` is null, or a triangle index is out of range;
/// std::system_error naming the file on I/O failure (the target is then left as it was).
void write_shell_mesh(const std::string& path, const MeshFrame& mesh, MeshFormat format);

}  // namespace shellmpm

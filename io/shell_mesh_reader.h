// Shell control meshes from files (anything assimp reads), with named vertex groups.
#pragma once
#include <string>

#include "sim/scene/shell_mesh.h"

namespace shellmpm {

/// Reads every mesh of a file into one ShellMesh: one control point per position.
///
/// - Reading follows read_mesh (io/mesh_reader.h): polygons are triangulated, points
///   and lines dropped, every mesh placed by its node's accumulated transform,
///   vertices first joined as aiProcess_JoinIdenticalVertices does, `uvs` = texture
///   channel 0 when every mesh has it, else empty.
/// - Then vertices with identical positions (exactly equal coordinates; -0 == +0) are
///   merged, also across meshes: a shell needs one control point per geometric
///   position, so hard edges and UV seams do not split it and separately stored parts
///   that share boundary vertices are stitched. The first occurrence is kept (control
///   points are numbered in order of first occurrence). Triangles are remapped.
/// - UVs stay per corner: `uvs` holds one entry per distinct (control point, UV) pair
///   (exactly equal values; numbered in order of first occurrence) and `uv_triangles`
///   each corner's entry, so a control point on a UV seam has several entries and the
///   output meshes split there (LimitMesh). Without seams uv_triangles == triangles.
/// - Groups: the name of every assimp mesh and of every node (OBJ `o` and `g` names,
///   glTF node and mesh names, ...) becomes a group holding the sorted unique control
///   points of its triangles (a node's group includes its children's meshes). Equal
///   names are united. Empty names, the root node's name unless the root holds meshes
///   itself (assimp names it after the file for OBJ), and "defaultobject" (assimp's
///   name for OBJ faces before any `o`/`g`) are not groups.
///
/// @param path  the mesh file
/// @param where the location that named the file, for messages ("file:line: key",
///              "file: key" or "file"; see read_mesh).
/// @throws UserError at `where`, naming `path`, when the file is missing or unreadable,
///         has no triangles, has a non-finite coordinate, or has a triangle with two
///         corners at the same position (degenerate after merging).
ShellMesh read_shell_mesh(const std::string& path, const std::string& where);

}  // namespace shellmpm

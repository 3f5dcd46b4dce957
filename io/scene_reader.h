// Reads a scene file (YAML or JSON) into a Scene, validating every key against one schema
// (io/scene_schema.h), which drives the validation, fills the structs and is what
// docs/scene-format.md documents; a test keeps the two in step.
#pragma once
#include <limits>
#include <string>
#include <vector>

#include "io/scene_schema.h"
#include "io/user_error.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// Positions that place simulated things (the domain corners, collider shapes and
/// keyframes, pin keyframes) must lie within this many cells (shot.dx) of the origin: up to
/// 2^17 cells a float position is resolved to 1/64 of a cell (ulp(2^17 dx) = dx/64). The
/// same bound holds in a double build, so a scene valid in one build is valid in the other.
constexpr double kPositionRangeCells = 131072.0;  // 2^17

/// The most steps one frame may take at the smallest step: 1 / (fps dt_min) <= this.
constexpr double kMaxStepsPerFrame = 1e7;

/// Parses and validates a scene file. Mesh paths are resolved relative to the scene file and
/// must name readable files; meshes are not loaded (ShapeDesc::sdf stays empty).
/// @param overrides "key.path=value" strings (from `--set`), applied in order to the document
///   before validation; the value is parsed as YAML and replaces the whole value at that key.
/// @throws UserError naming file, line and key for any problem with the file or an override.
Scene read_scene(const std::string& path, const std::vector<std::string>& overrides = {});

/// Checks the pin and point-load indices of `shell` against its vertex count, for meshes
/// whose count is known only once the file is loaded (the reader checks procedural geometry
/// itself). Call it from io/ after loading ShellDesc::mesh.
/// @param num_vertices number of control points of the shell's mesh (>= 0)
/// @param scene_path   the scene file, for messages when a pin or load has no `where`
/// @throws UserError at the offending key ("file:line: shells[0].pins[1].indices[3]", from
///   PinDesc::where / PointLoadDesc::where) when an index is >= num_vertices.
void check_shell_indices(const ShellDesc& shell, int num_vertices, const std::string& scene_path);

/// As read_scene, from text; `path` is used for messages and to resolve relative mesh paths.
Scene parse_scene(const std::string& text, const std::string& path,
                  const std::vector<std::string>& overrides = {});

}  // namespace shellmpm

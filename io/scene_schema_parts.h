// The scene format's table in parts (io/scene_schema_table.cpp: the top level, the shot,
// bulk materials, sources and colliders; scene_schema_shells.cpp: shell materials, shells
// and their geometry; scene_schema_outputs.cpp: pre-roll, outputs, previews and shapes):
// what the parts share. The table's order is the parts' order.
#pragma once
#include <string>
#include <vector>

#include "io/scene_spec.h"

namespace shellmpm::scenefile {

/// Position keys that place simulated things off the grid (keyframes, collider shapes):
/// within the range where Real resolves 1/64 of a cell (see kPositionRangeCells).
inline constexpr const char* kInPositionRange = "each coordinate within 2^17 dx of the origin";
/// Output file names (patterns, stats): inside output.directory.
inline constexpr const char* kOutputFile = "a relative file name; its folders are created";

/// The keys of one keyframe list item under `prefix` ("colliders[].keyframes[]").
std::vector<KeySpec> keyframe_specs(const std::string& prefix);

/// Shell materials, shells and their geometry (scene_schema_shells.cpp).
std::vector<KeySpec> shell_keys();
/// Pre-roll, outputs, previews, and the shapes of sources and colliders
/// (scene_schema_outputs.cpp).
std::vector<KeySpec> output_keys();

}  // namespace shellmpm::scenefile

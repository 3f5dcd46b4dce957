// The "resolved" block of run.json: the settings a tool outside shellmpm needs to read a
// run folder without parsing the scene file (YAML) itself: frames and fps, the cache axes,
// the file patterns of every cache the run writes, the shells and their preview colours,
// and the cameras. tools/blender/shellmpm_import.py reads it (docs/blender.md).
#pragma once
#include <nlohmann/json.hpp>

#include "sim/scene/scene.h"

namespace shellmpm {

/// The resolved settings of `scene` as one JSON object:
///   fps (number), frames [first, last], up_axis ("y" | "z": the up axis of the caches),
///   units (string), size [width, height] (render.size, pixels),
///   density {pattern, grid: "density", velocity_grid: "vel" | null, extinction [1/m]}
///     or null when the run writes no density volumes,
///   particles {pattern} or null,
///   shells [{name, pattern (the shell's own, "{name}" filled in), format ("ply" | "obj"
///     | "glb"), front_color, back_color (linear RGB)}] for the shells whose mesh is
///     written, in scene order,
///   cameras [{name, position, target, up, fov (vertical, degrees)}] (render.cameras),
///   camera (the name of the camera previews use, or "auto"),
///   domain {min, max}.
/// Positions (cameras, domain) are in scene coordinates (Y up); patterns are relative to
/// the output directory, with one run of '#' for the zero-padded frame number.
nlohmann::json resolved_run_settings(const Scene& scene);

}  // namespace shellmpm

// Loads and validates the control meshes of a scene's shells.
#pragma once
#include "sim/scene/scene.h"

namespace shellmpm {

/// Reads every mesh-file shell (vertex groups kept), checks every shell's control mesh
/// (non-manifold edges, duplicate vertices, zero-area faces, inconsistent orientation)
/// and the pin and point-load indices against its vertex count.
/// @throws UserError naming the scene file, line and key.
void load_shell_meshes(Scene& scene);

}  // namespace shellmpm

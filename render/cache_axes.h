// Caches back in the simulation's axes. A run may write its caches Z-up
// (output.up_axis; sim/scene/output_axes.h); the preview renderer turns what it reads
// back to Y-up, so a preview does not depend on up_axis (the camera, colliders and ground
// are in the scene's Y-up axes). The rotation is a permutation and a sign, so the data
// comes back bit for bit as a Y-up run wrote it.
#pragma once
#include <vector>

#include "render/preview_scene.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// Positions and normals of a mesh read from a file written with axes `up`, in place.
void mesh_from_output_axes(RenderMesh& mesh, UpAxis up);

/// Points read from a file written with axes `up`, in place.
void points_from_output_axes(std::vector<Vec3f>& points, UpAxis up);

}  // namespace shellmpm

// Bounds that need the scene's meshes: every source inside the domain, every shell inside
// the domain (contact) or the position range, its control mesh resolvable in float, mesh
// colliders within the position range. The reader checks what the scene file alone
// decides (io/scene_reader.h); this runs once the meshes are loaded.
#pragma once
#include "sim/scene/scene.h"

namespace shellmpm {

/// Call after load_scene_assets and load_shell_meshes. Checks, without sampling particles
/// or building the solver:
///  - each source's particles lie one cell inside shot.domain (the shape's bounds, and
///    only where they reach past it, the lattice points themselves);
///  - each shell's placed rest mesh is finite; with contact, one cell inside the domain,
///    else within kPositionRangeCells cells of the origin;
///  - each shell's shortest rest edge spans at least 2^8 float steps at the shell's
///    distance from the origin (ulp(|x|) * 256, i.e. |x| * 2^-15), so its strains are not
///    float round-off;
///  - each mesh collider's bounds lie within kPositionRangeCells cells of the origin.
/// @throws UserError naming the file, line and key (sources[i].shape, shells[i].translate,
///   colliders[i].shape.path).
void check_scene_bounds(const Scene& scene);

}  // namespace shellmpm

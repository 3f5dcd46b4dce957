// Hidden-particle culling for previews: in a pile of touching spheres only the outer
// layers can be seen, or cast shadows. Both render paths draw the particles that survive.
#pragma once
#include <cstddef>

#include "render/preview_scene.h"

namespace shellmpm {

/// Removes the particles that are buried: the cells of a grid of spacing 3 x radius are
/// marked where a particle lies, and a particle whose cell and all 26 neighbouring cells
/// are marked, and whose cell is at least two cells from an unmarked one, is dropped
/// (at the default radius, half the particle spacing, every cell of packed material holds
/// a particle, so buried particles are hidden behind at least two full cells). Keeps the
/// order of the survivors; deterministic. Skipped (nothing removed) when the particles'
/// bounds would need more than 2^27 cells.
/// @return the number of particles removed.
std::size_t cull_hidden_particles(RenderParticles& particles);

}  // namespace shellmpm

// Per-frame particle cache: binary little-endian PLY point cloud with position,
// velocity and id (readable by Houdini, Blender and any PLY reader).
#pragma once
#include <string>

#include "sim/mpm/particles.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// Writes positions (x y z), velocities (vx vy vz) as float and id as uint, atomically,
/// in the axes `up` (sim/scene/output_axes.h: Z turns each float triple (x, y, z) into
/// (x, -z, y) and adds the header comment "up_axis z").
void write_particle_ply(const std::string& path, const ParticleSet& p, UpAxis up = UpAxis::Y);

}  // namespace shellmpm

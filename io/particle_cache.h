// Per-frame particle cache: binary little-endian PLY point cloud with position,
// velocity and id (readable by Houdini, Blender and any PLY reader).
#pragma once
#include <string>

#include "sim/mpm/particles.h"

namespace shellmpm {

/// Writes positions (x y z), velocities (vx vy vz) as float and id as uint, atomically.
void write_particle_ply(const std::string& path, const ParticleSet& p);

}  // namespace shellmpm

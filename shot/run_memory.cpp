#include "shot/run_memory.h"

#include <algorithm>
#include <cmath>

#include "sim/core/types.h"

namespace shellmpm {
namespace {

constexpr double kVec3 = sizeof(Vec3), kMat3 = sizeof(Mat3), R = sizeof(Real);

}  // namespace

RunMemory estimate_run_memory(const Scene& scene, double baseline) {
  RunMemory m;
  m.solver = estimate_solver_memory(scene);
  m.baseline = baseline;
  const MemoryCounts& n = m.solver.counts;
  const OutputSettings& o = scene.output;
  const double particles = n.peak_particles();
  auto consider = [&](double bytes, const char* what) {
    if (bytes > m.writers) {
      m.writers = bytes;
      m.writer = what;
    }
  };
  if (o.density && !scene.sources.empty()) {
    // io/density_vdb.cpp: per particle a (leaf key, index) pair, a stencil (3 bases and 9
    // double weights) and, with velocity, a Vec3d; then the leaves of 8^3 voxels (floats,
    // Vec3s for velocity) over the occupied volume and a voxel around it.
    const double h = o.voxel_size > 0 ? o.voxel_size : scene.shot.dx;
    double rest_volume = 0;
    for (const SourceDesc& s : scene.sources)
      rest_volume += expected_source_particles(s, scene.shot) * std::pow(scene.shot.dx, 3) /
                     s.particles_per_cell;
    const double leaves = 2.0 * rest_volume / std::pow(8 * h, 3) + 8;
    const double leaf = 512 * 4 + 160 + (o.velocity ? 512 * 12 + 160 : 0);
    consider(particles * (16 + 88 + (o.velocity ? 24 : 0)) + leaves * leaf, "density VDB");
  }
  if (o.particles && !scene.sources.empty()) consider(24 * particles, "particle cache");
  if (o.checkpoint_every > 0) {
    // A copy of the particles and of each shell's state (positions, velocities, denting
    // state, contact APIC matrices and normal columns).
    bool denting = false;
    for (const ShellDesc& sh : scene.shells)
      denting = denting || scene.shell_materials[sh.material].yield_stress > 0;
    const double shells = n.shell_points * (2 * kVec3 + kMat3) + n.contact_sites * kVec3 +
                          (denting ? n.quadrature_points * 4 * R * 5 : 0);
    consider(m.solver.bytes_per_particle * particles + shells, "checkpoint");
  }
  {
    // Shell meshes: limit positions and normals, then the encoded file in memory (OBJ is
    // text, about 80 bytes a vertex and 40 a triangle; PLY and GLB are binary).
    const bool text = o.shell_format == MeshFormat::Obj;
    // With output.velocity, PLY and GLB also carry a velocity (a Vec3 and 12 bytes a vertex).
    const bool vel = o.velocity && !text;
    const double per_vertex = (vel ? 3 : 2) * kVec3 + (text ? 80 : 32) + (vel ? 12 : 0);
    const double per_triangle = text ? 40 : 13;
    consider(n.output_vertices * per_vertex + 2 * n.output_vertices * per_triangle, "shell meshes");
  }
  // A run touches more of its libraries than check has (OpenVDB's registry and writer,
  // compression, file buffers, worker threads): measured 6 to 7 MiB over check's process
  // for a run of a tiny scene.
  constexpr double kRunOverhead = 8.0 * 1024 * 1024;
  m.peak = baseline + kRunOverhead +
           std::max(m.solver.construction_bytes,
                    m.solver.held_bytes + std::max(m.solver.step_scratch, m.writers));
  return m;
}

}  // namespace shellmpm

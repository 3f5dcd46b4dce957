// How much memory the solver of a scene will hold at its peak, from the scene alone:
// particle counts from the source shapes, control points, quadrature points and contact
// particles from the shells' control meshes, grid blocks from the occupied region. Nothing
// of the shot is allocated (check runs it on scenes too large to build).
//
// The model follows the solver's arrays (sizeof of their elements, Real included) and
// the phases in which they coexist: the shells are built one after the other (each with
// the basis of every quadrature point, freed once the Kirchhoff-Love data is built), then
// contact and the integrity monitor, then the particles of the fill sources; a step adds
// the grid, per-shell grids and force buffers. Writers of the run (VDB, caches,
// checkpoints) add their own transients: shot/run_memory.h.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "sim/scene/scene.h"

namespace shellmpm {

/// Whether shell i of `scene` has contact (its control points on the grid), as the
/// solver decides it: On, or Auto when the scene has a collider, a source or another shell.
bool shell_contact_on(const Scene& scene, std::size_t i);

/// The counts the estimate is built from (expected values, not exact: the particle count
/// of a shape is its volume times particles_per_cell / dx^3).
struct MemoryCounts {
  double fill_particles = 0;     ///< bulk particles of the fill sources at the start
  double emitted_particles = 0;  ///< bulk particles the emitting sources add in all
  double particle_blocks = 0;    ///< occupied 4^3-cell blocks of the combined grid
  double grid_blocks = 0;        ///< their grid blocks (each particle block and its +1 neighbours)
  double shell_points = 0;       ///< control points of all shells
  double largest_shell = 0;      ///< control points of the largest shell
  double shell_triangles = 0;    ///< control-mesh triangles of all shells
  double quadrature_points = 0;  ///< Kirchhoff-Love in-plane quadrature points, all shells
  double contact_sites = 0;      ///< contact particles (shells with contact)
  double output_vertices = 0;    ///< limit-mesh vertices written per frame, all shells
  double peak_particles() const { return fill_particles + emitted_particles; }
};

/// One part of the estimate, e.g. {"particles", 1.2e8}.
struct MemoryPart {
  std::string what;
  double bytes = 0;
};

struct SolverMemory {
  MemoryCounts counts;
  /// What the solver holds during a step at the peak particle count, by part.
  std::vector<MemoryPart> parts;
  double held_bytes = 0;          ///< sum of parts: what stays allocated between steps
  double step_scratch = 0;        ///< temporaries of a step or of the end-of-frame sort
  double construction_bytes = 0;  ///< the most held while the solver is built
  double step_bytes() const { return held_bytes + step_scratch; }
  double peak_bytes() const {
    return step_bytes() > construction_bytes ? step_bytes() : construction_bytes;
  }
  /// Bytes of one ParticleSet entry (its attribute arrays).
  double bytes_per_particle = 0;
};

/// The estimate for `scene`. Mesh shells need ShellDesc::mesh and mesh sources
/// ShapeDesc::sdf loaded (io/ does both when it reads a scene for a command).
SolverMemory estimate_solver_memory(const Scene& scene);

/// Expected bulk particles of one source: a fill source's initial count, or what an
/// emitting source releases over its whole window (rest density times the flow through
/// the shape's cross-section along the velocity).
double expected_source_particles(const SourceDesc& src, const ShotSettings& shot);

}  // namespace shellmpm

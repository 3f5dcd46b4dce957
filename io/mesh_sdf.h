// Signed distance fields of closed triangle meshes (OpenVDB mesh-to-volume), sampled
// into the dense SdfGrid that sim/ reads, and the scene step that loads mesh shapes.
#pragma once
#include <memory>
#include <string>

#include "io/mesh_reader.h"
#include "sim/scene/scene.h"
#include "sim/scene/sdf_grid.h"

namespace shellmpm {

/// The signed distance to a closed mesh, negative inside, on a dense grid.
///
/// Built with openvdb::tools::meshToVolume: exact distances in a band of
/// `half_band_voxels` voxels outside the surface and everywhere inside (the interior
/// band is unlimited, so deep interior points hold their true negative distance, not
/// a clamped one). Inside/outside comes from OpenVDB's flood fill of the voxelized
/// surface, so the winding and normals of the mesh do not matter, but the surface
/// must be closed (holes smaller than a voxel are tolerated).
/// The dense grid covers the mesh bounding box padded by half_band_voxels + 2 voxels
/// on each side; samples beyond the outside band read +half_band_voxels * voxel_size,
/// and SdfGrid::sample extends the field outside the box.
///
/// @param voxel_size sample spacing [m], > 0
/// @param half_band_voxels exterior band width in voxels, >= 1
/// @param where as in read_mesh, for messages
/// @throws UserError at `where` when the mesh does not enclose a volume (no sample
///   inside, or the inside reaches the padded border: an open mesh), or when the
///   grid would exceed 2^28 samples (voxel size too small for the mesh).
std::shared_ptr<const SdfGrid> mesh_to_sdf(const TriMesh& mesh, double voxel_size,
                                           int half_band_voxels, const std::string& where);

/// Loads every mesh shape of the scene's sources and colliders: reads
/// ShapeDesc::mesh_path, scales it about the origin by mesh_scale, then translates it by
/// mesh_translate, and fills ShapeDesc::sdf with spacing shot.dx / 2 (band: 3 voxels
/// for sources, which only need the sign; 8 voxels = 4 dx for colliders, so the
/// distance and normal are exact where particles approach). Shapes already holding an
/// sdf are left alone; identical (path, scale, translate) triples share one grid.
/// Messages name scene.path and the key, e.g. "sources[0].shape.path".
/// @throws UserError as read_mesh and mesh_to_sdf, and for a non-positive mesh_scale.
void load_scene_assets(Scene& scene);

}  // namespace shellmpm

// OpenVDB grids in the output axes (output.up_axis; sim/scene/output_axes.h). A grid whose
// transform is a uniform scale (voxel (i, j, k) centred at (i, j, k) h) is turned from
// Y-up to Z-up by moving voxel (i, j, k) to (i, -k, j) and turning its vector value the
// same way: the volume is rotated exactly, with no resampling, and the transform, voxel
// size and metadata stay as they are. Header-only, for the VDB writer (io/density_vdb.cpp)
// and the preview renderer, which turns caches back (render/cache_axes.h).
#pragma once
#include <openvdb/openvdb.h>

#include "sim/scene/output_axes.h"

namespace shellmpm {

/// The index of a Y-up voxel in the grid written with axes `up`: (i, -k, j) for Z.
inline openvdb::Coord to_output_axes(const openvdb::Coord& c, UpAxis up) {
  return up == UpAxis::Y ? c : openvdb::Coord(c.x(), -c.z(), c.y());
}

/// The inverse of to_output_axes(Coord): (i, k, -j) for Z.
inline openvdb::Coord from_output_axes(const openvdb::Coord& c, UpAxis up) {
  return up == UpAxis::Y ? c : openvdb::Coord(c.x(), c.z(), -c.y());
}

/// A copy of `grid` (transform, metadata, class and background deep-copied) whose active
/// values v at index c are moved to coord_map(c) with value value_map(v). Active tiles
/// become voxels. Serial, so the result does not depend on the thread count.
template <class GridT, class CoordMap, class ValueMap>
typename GridT::Ptr remap_voxels(const GridT& grid, CoordMap coord_map, ValueMap value_map) {
  typename GridT::Ptr out = grid.copyWithNewTree();
  auto acc = out->getAccessor();
  for (auto it = grid.cbeginValueOn(); it; ++it) {
    const typename GridT::ValueType v = value_map(*it);
    if (it.isVoxelValue()) {
      acc.setValue(coord_map(it.getCoord()), v);
      continue;
    }
    openvdb::CoordBBox box;
    it.getBoundingBox(box);
    for (auto c = box.begin(); c; ++c) acc.setValue(coord_map(*c), v);
  }
  return out;
}

/// A scalar grid written Y-up, in the axes `up` (the grid itself when up is Y).
template <class GridT>
typename GridT::Ptr scalar_grid_to_output_axes(const typename GridT::Ptr& grid, UpAxis up) {
  if (up == UpAxis::Y) return grid;
  return remap_voxels(
      *grid, [](const openvdb::Coord& c) { return to_output_axes(c, UpAxis::Z); },
      [](const typename GridT::ValueType& v) { return v; });
}

/// A scalar grid read in the axes `up`, back in the simulation's (the grid itself for Y).
template <class GridT>
typename GridT::Ptr scalar_grid_from_output_axes(const typename GridT::Ptr& grid, UpAxis up) {
  if (up == UpAxis::Y) return grid;
  return remap_voxels(
      *grid, [](const openvdb::Coord& c) { return from_output_axes(c, UpAxis::Z); },
      [](const typename GridT::ValueType& v) { return v; });
}

/// A vec3 grid written Y-up, in the axes `up`: voxels moved and vectors turned.
inline openvdb::Vec3SGrid::Ptr vector_grid_to_output_axes(const openvdb::Vec3SGrid::Ptr& grid,
                                                          UpAxis up) {
  if (up == UpAxis::Y) return grid;
  return remap_voxels(
      *grid, [](const openvdb::Coord& c) { return to_output_axes(c, UpAxis::Z); },
      [](const openvdb::Vec3s& v) { return openvdb::Vec3s(v.x(), -v.z(), v.y()); });
}

}  // namespace shellmpm

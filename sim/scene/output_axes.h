// The rotation between the simulation's axes (always Y up) and the axes a run writes its
// caches in (output.up_axis). Y-up to Z-up is the right-handed rotation by +90 degrees
// about X: (x, y, z) -> (x, -z, y), so +Y goes to +Z and +Z to -Y, and X stays. It only
// permutes components and flips a sign, so it is exact in floating point: a cache
// written Z-up and turned back holds the same bits as one written Y-up.
#pragma once
#include <Eigen/Core>
#include <cstddef>

#include "sim/scene/scene.h"

namespace shellmpm {

/// `v` (a position, normal or velocity) in the output axes: unchanged for UpAxis::Y,
/// (x, -z, y) for UpAxis::Z.
template <class T>
Eigen::Matrix<T, 3, 1> to_output_axes(const Eigen::Matrix<T, 3, 1>& v, UpAxis up) {
  if (up == UpAxis::Y) return v;
  return Eigen::Matrix<T, 3, 1>(v.x(), -v.z(), v.y());
}

/// The inverse of to_output_axes: unchanged for UpAxis::Y, (x, z, -y) for UpAxis::Z.
template <class T>
Eigen::Matrix<T, 3, 1> from_output_axes(const Eigen::Matrix<T, 3, 1>& v, UpAxis up) {
  if (up == UpAxis::Y) return v;
  return Eigen::Matrix<T, 3, 1>(v.x(), v.z(), -v.y());
}

/// The axes a shell mesh file of `format` is written in when the scene asks for `up`:
/// `up` for PLY and OBJ; always Y for GLB, because glTF 2.0 defines +Y as up (spec
/// section 3.4, "Coordinate System and Units") and importers (Blender's, Houdini's)
/// convert from it to their own axes, so a Z-up glTF would arrive rotated twice.
inline UpAxis mesh_file_up_axis(MeshFormat format, UpAxis up) {
  return format == MeshFormat::Glb ? UpAxis::Y : up;
}

/// to_output_axes on `count` packed (x, y, z) triples in place.
template <class T>
void to_output_axes(T* xyz, std::size_t count, UpAxis up) {
  if (up == UpAxis::Y) return;
  for (std::size_t i = 0; i < count; ++i) {
    T* p = xyz + 3 * i;
    const T y = p[1];
    p[1] = -p[2];
    p[2] = y;
  }
}

}  // namespace shellmpm

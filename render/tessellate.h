// Triangle meshes of the analytic collider shapes, and vertex normals of triangle soups.
#pragma once
#include "render/preview_scene.h"
#include "sim/core/types.h"
#include "sim/scene/scene.h"

namespace shellmpm {

/// A UV sphere: `segments` around the equator, segments / 2 rings; outward normals. Its
/// silhouette area is within 0.2% of the sphere's for segments >= 64.
RenderMesh tessellate_sphere(const Vec3d& center, double radius, int segments = 96);
/// A box [lo, hi] with flat faces (24 vertices).
RenderMesh tessellate_box(const Vec3d& lo, const Vec3d& hi);
/// A closed cylinder around `axis` (unit) through `center`, `height` long.
RenderMesh tessellate_cylinder(const Vec3d& center, const Vec3d& axis, double radius, double height,
                               int segments = 96);
/// A square of half-size `half` on the plane through `center` with unit `normal`, split
/// into n x n quads (so per-vertex work stays local), front side along the normal.
RenderMesh tessellate_square(const Vec3d& center, const Vec3d& normal, double half, int n = 8);

/// The analytic shape in its own frame (box, sphere, cylinder). Planes and meshes are
/// handled by the caller. @throws std::invalid_argument for other kinds.
RenderMesh tessellate_shape(const ShapeDesc& shape);

/// Area-weighted vertex normals (unit; +Y for vertices of degenerate triangles only).
std::vector<Vec3f> vertex_normals(const std::vector<Vec3f>& positions,
                                  const std::vector<Eigen::Vector3i>& triangles);

}  // namespace shellmpm

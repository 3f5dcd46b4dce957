#include "render/cache_axes.h"

#include "sim/scene/output_axes.h"

namespace shellmpm {

void mesh_from_output_axes(RenderMesh& mesh, UpAxis up) {
  points_from_output_axes(mesh.positions, up);
  points_from_output_axes(mesh.normals, up);
}

void points_from_output_axes(std::vector<Vec3f>& points, UpAxis up) {
  if (up == UpAxis::Y) return;
  for (Vec3f& p : points) p = from_output_axes(p, up);
}

}  // namespace shellmpm

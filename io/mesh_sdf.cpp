#include "io/mesh_sdf.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>
#include <unordered_map>

#include "sim/core/check.h"
#include "sim/core/parallel.h"

namespace shellmpm {
namespace {

/// MeshDataAdapter (see openvdb/tools/MeshToVolume.h) over a TriMesh, in index space
/// of a linear transform with voxel size h (world = index * h).
struct TriMeshAdapter {
  const TriMesh& mesh;
  double inv_h;
  std::size_t polygonCount() const { return mesh.triangles.size(); }
  std::size_t pointCount() const { return mesh.vertices.size(); }
  std::size_t vertexCount(std::size_t) const { return 3; }
  void getIndexSpacePoint(std::size_t n, std::size_t v, openvdb::Vec3d& pos) const {
    const Vec3d& p =
        mesh.vertices[static_cast<std::size_t>(mesh.triangles[n][static_cast<int>(v)])];
    pos = openvdb::Vec3d(p.x() * inv_h, p.y() * inv_h, p.z() * inv_h);
  }
};

/// Edges used by exactly one triangle, with vertices welded by exact position
/// (assimp keeps seam vertices apart), for the message about an open mesh.
std::size_t count_open_edges(const TriMesh& mesh) {
  std::map<std::tuple<double, double, double>, int> weld;
  std::vector<int> id(mesh.vertices.size());
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    const auto& p = mesh.vertices[v];
    id[v] = weld.emplace(std::make_tuple(p.x(), p.y(), p.z()), static_cast<int>(weld.size()))
                .first->second;
  }
  std::unordered_map<std::uint64_t, int> uses;
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) {
      std::uint64_t a = static_cast<std::uint32_t>(id[t[e]]);
      std::uint64_t b = static_cast<std::uint32_t>(id[t[(e + 1) % 3]]);
      if (a == b) continue;
      if (a > b) std::swap(a, b);
      ++uses[(a << 32) | b];
    }
  std::size_t open = 0;
  for (const auto& [edge, count] : uses) open += count == 1 ? 1 : 0;
  return open;
}

/// The dense sample box: the mesh's bounding box in index space of voxel size h, padded
/// by pad voxels (lowest index ilo, dims); returns the sample count, or a UserError at
/// `where` when it is too large.
double dense_box(const TriMesh& mesh, double h, int pad, const std::string& where, Vec3i& ilo,
                 Vec3i& dims) {
  Vec3d lo = mesh.vertices[0], hi = lo;
  for (const auto& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  double samples = 1;
  for (int a = 0; a < 3; ++a) {
    const double l = std::floor(lo[a] / h) - pad, u = std::ceil(hi[a] / h) + pad;
    if (!(std::abs(l) < 1e9 && std::abs(u) < 1e9 && u - l + 1 < 1e9))
      throw detail::user_error_at(where, "mesh is too large for the voxel size");
    ilo[a] = static_cast<int>(l);
    dims[a] = static_cast<int>(u - l) + 1;
    samples *= dims[a];
  }
  if (samples > double(1 << 28)) {
    std::ostringstream os;
    os << "mesh extent " << (hi - lo).transpose() << " m needs " << samples
       << " distance samples at voxel size " << h << " m (limit 2^28); use a coarser shot.dx "
       << "or a smaller mesh";
    throw detail::user_error_at(where, os.str());
  }
  return samples;
}

/// Throws a UserError at `where` unless the sampled distance encloses a volume: some
/// sample clearly inside (samples on a face that lies on a grid plane read -1e-7 for open
/// meshes too), and the padded border entirely outside.
void check_enclosed(const SdfGrid& sdf, const TriMesh& mesh, const std::string& where) {
  const double h = sdf.spacing;
  const std::size_t nx = static_cast<std::size_t>(sdf.dims.x()),
                    ny = static_cast<std::size_t>(sdf.dims.y()),
                    nz = static_cast<std::size_t>(sdf.dims.z());
  const float deep = static_cast<float>(-0.25 * h);
  bool any_inside = false, border_inside = false;
  for (std::size_t k = 0; k < nz; ++k)
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        const float v = sdf.values[(k * ny + j) * nx + i];
        if (!(v < 0)) continue;
        any_inside = any_inside || v < deep;
        const bool border = i == 0 || j == 0 || k == 0 || i + 1 == nx || j + 1 == ny || k + 1 == nz;
        border_inside = border_inside || border;
      }
  if (!any_inside || border_inside) {
    std::ostringstream os;
    os << "mesh does not enclose a volume at voxel size " << h << " m ("
       << (any_inside ? "its inside leaks to the outside" : "no point is inside") << "; "
       << count_open_edges(mesh) << " open edges of " << mesh.triangles.size()
       << " triangles); sources and colliders need a closed mesh thicker than a voxel";
    throw detail::user_error_at(where, os.str());
  }
}

}  // namespace

std::shared_ptr<const SdfGrid> mesh_to_sdf(const TriMesh& mesh, double voxel_size,
                                           int half_band_voxels, const std::string& where) {
  SHELLMPM_CHECK(voxel_size > 0 && std::isfinite(voxel_size), "voxel_size " << voxel_size);
  SHELLMPM_CHECK(half_band_voxels >= 1, "half_band_voxels " << half_band_voxels);
  if (mesh.triangles.empty()) throw detail::user_error_at(where, "mesh has no triangles");
  const double h = voxel_size;
  openvdb::initialize();
  Vec3i ilo, dims;
  const double samples = dense_box(mesh, h, half_band_voxels + 2, where, ilo, dims);

  auto xform = openvdb::math::Transform::createLinearTransform(h);
  const float band = static_cast<float>(half_band_voxels);
  openvdb::FloatGrid::Ptr grid = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      TriMeshAdapter{mesh, 1.0 / h}, *xform, band, std::numeric_limits<float>::max());

  auto sdf = std::make_shared<SdfGrid>();
  sdf->origin = ilo.cast<double>() * h;
  sdf->spacing = h;
  sdf->dims = dims;
  const float outside = static_cast<float>(half_band_voxels * h);
  sdf->background = outside;
  sdf->values.assign(static_cast<std::size_t>(samples), outside);
  const std::size_t nx = static_cast<std::size_t>(dims.x()),
                    ny = static_cast<std::size_t>(dims.y());
  parallel_for(static_cast<std::size_t>(dims.z()), 1, [&](std::size_t kb, std::size_t ke) {
    openvdb::FloatGrid::ConstAccessor acc = grid->getConstAccessor();
    for (std::size_t k = kb; k < ke; ++k)
      for (std::size_t j = 0; j < ny; ++j)
        for (std::size_t i = 0; i < nx; ++i) {
          const openvdb::Coord c(ilo.x() + static_cast<int>(i), ilo.y() + static_cast<int>(j),
                                 ilo.z() + static_cast<int>(k));
          sdf->values[(k * ny + j) * nx + i] = std::min(acc.getValue(c), outside);
        }
  });
  check_enclosed(*sdf, mesh, where);
  return sdf;
}

void load_scene_assets(Scene& scene) {
  std::map<std::tuple<std::string, double, double, double, double, int>,
           std::shared_ptr<const SdfGrid>>
      cache;
  auto load = [&](ShapeDesc& shape, const std::string& key, int band) {
    if (shape.kind != ShapeDesc::Kind::Mesh || shape.sdf) return;
    const std::string where = shape.mesh_where.empty() ? scene.path + ": " + key : shape.mesh_where;
    if (!(shape.mesh_scale > 0) || !std::isfinite(shape.mesh_scale)) {
      std::ostringstream os;
      os << "mesh scale must be > 0, got " << shape.mesh_scale;
      throw detail::user_error_at(where, os.str());
    }
    const auto id = std::make_tuple(shape.mesh_path, shape.mesh_scale, shape.mesh_translate.x(),
                                    shape.mesh_translate.y(), shape.mesh_translate.z(), band);
    auto& slot = cache[id];
    if (!slot) {
      TriMesh mesh = read_mesh(shape.mesh_path, where);
      for (auto& v : mesh.vertices) v = v * shape.mesh_scale + shape.mesh_translate;
      slot = mesh_to_sdf(mesh, scene.shot.dx / 2, band, where);
    }
    shape.sdf = slot;
  };
  for (std::size_t i = 0; i < scene.sources.size(); ++i)
    load(scene.sources[i].shape, "sources[" + std::to_string(i) + "].shape.path", 3);
  for (std::size_t i = 0; i < scene.colliders.size(); ++i)
    load(scene.colliders[i].shape, "colliders[" + std::to_string(i) + "].shape.path", 8);
}

}  // namespace shellmpm

#include "render/scene_assembler.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "io/atomic_file.h"
#include "io/mesh_reader.h"
#include "io/ply_reader.h"
#include "io/user_error.h"
#include "io/vdb_axes.h"
#include "render/cache_axes.h"
#include "render/particle_culling.h"
#include "render/tessellate.h"
#include "sim/collider/collider.h"
#include "sim/collider/shape_sdf.h"
#include "sim/core/check.h"
#include "sim/scene/output_axes.h"
#include "sim/scene/scene_words.h"

namespace shellmpm {
namespace {

namespace fs = std::filesystem;

Vec3f to_f(const Vec3d& v) {
  return v.cast<float>();
}

constexpr std::size_t kMaxDenseVoxels = std::size_t(32) << 20;

/// Throws a CacheError unless the cache file `path` exists.
void require_cache_file(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw CacheError(path, "missing (the run did not write this frame)");
}

/// A PLY cache file, or a CacheError naming it.
PlyMesh read_ply_cache(const std::string& path) {
  require_cache_file(path);
  try {
    return read_ply(path);
  } catch (const std::runtime_error& e) {
    throw CacheError(path, std::string(e.what()).substr(path.size() + 2));
  }
}

/// The density grid of a VDB cache, or a CacheError naming it.
openvdb::FloatGrid::Ptr read_density_grid(const std::string& path) {
  require_cache_file(path);
  try {
    openvdb::io::File file(path);
    file.open(false);
    if (!file.hasGrid("density")) throw CacheError(path, "has no grid named 'density'");
    openvdb::GridBase::Ptr base = file.readGrid("density");
    file.close();
    auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid) throw CacheError(path, "grid 'density' is not a float grid");
    return grid;
  } catch (const openvdb::Exception& e) {
    throw CacheError(path, std::string("unreadable VDB: ") + e.what());
  } catch (const CacheError&) {
    throw;
  } catch (const std::exception& e) {
    throw CacheError(path, std::string("unreadable VDB: ") + e.what());
  }
}

/// The fog volume made dense over its active voxels plus one voxel of zeros around them
/// (averaged down by an integer factor when that would exceed kMaxDenseVoxels).
RenderVolume dense_volume(const openvdb::FloatGrid& grid) {
  RenderVolume v;
  const openvdb::CoordBBox bb = grid.evalActiveVoxelBoundingBox();
  if (bb.empty()) return v;
  const openvdb::Coord dim = bb.dim();
  const double count = static_cast<double>(dim.x() + 2) * (dim.y() + 2) * (dim.z() + 2);
  const int f = std::max(1, static_cast<int>(std::ceil(std::cbrt(count / kMaxDenseVoxels))));
  v.dims = Eigen::Vector3i((dim.x() + f - 1) / f + 2, (dim.y() + f - 1) / f + 2,
                           (dim.z() + f - 1) / f + 2);
  const double h = grid.voxelSize()[0];
  v.voxel = static_cast<float>(h * f);
  // Dense sample (i, j, k) averages index voxels bb.min + (i-1, j-1, k-1) * f + [0, f)^3; its
  // center in world space:
  const openvdb::Vec3d c0 =
      grid.indexToWorld(openvdb::Vec3d(bb.min().x(), bb.min().y(), bb.min().z()) +
                        openvdb::Vec3d(0.5 * (f - 1)) - openvdb::Vec3d(f));
  v.origin =
      Vec3f(static_cast<float>(c0.x()), static_cast<float>(c0.y()), static_cast<float>(c0.z()));
  v.density.assign(static_cast<std::size_t>(v.dims.x()) * v.dims.y() * v.dims.z(), 0.0f);
  const float w = 1.0f / static_cast<float>(f * f * f);
  for (auto it = grid.cbeginValueOn(); it; ++it) {
    openvdb::CoordBBox vb;
    it.getBoundingBox(vb);
    const float val = *it * w;
    for (int z = vb.min().z(); z <= vb.max().z(); ++z)
      for (int y = vb.min().y(); y <= vb.max().y(); ++y)
        for (int x = vb.min().x(); x <= vb.max().x(); ++x) {
          const int i = (x - bb.min().x()) / f + 1, j = (y - bb.min().y()) / f + 1,
                    k = (z - bb.min().z()) / f + 1;
          v.density[(static_cast<std::size_t>(k) * v.dims.y() + j) * v.dims.x() + i] += val;
        }
  }
  return v;
}

RenderMesh iso_surface(const openvdb::FloatGrid& grid, double iso) {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> tris;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(grid, points, tris, quads, iso);
  RenderMesh m;
  m.kind = SurfaceKind::Bulk;
  m.name = "bulk surface";
  m.positions.reserve(points.size());
  for (const openvdb::Vec3s& p : points) m.positions.emplace_back(p.x(), p.y(), p.z());
  m.triangles.reserve(tris.size() + 2 * quads.size());
  for (const openvdb::Vec3I& t : tris)
    m.triangles.emplace_back(static_cast<int>(t[0]), static_cast<int>(t[1]),
                             static_cast<int>(t[2]));
  for (const openvdb::Vec4I& q : quads) {
    m.triangles.emplace_back(static_cast<int>(q[0]), static_cast<int>(q[1]),
                             static_cast<int>(q[2]));
    m.triangles.emplace_back(static_cast<int>(q[0]), static_cast<int>(q[2]),
                             static_cast<int>(q[3]));
  }
  m.normals = vertex_normals(m.positions, m.triangles);
  return m;
}

/// A mesh file (collider or source shape) scaled and translated as the simulation does.
RenderMesh shape_mesh_file(const ShapeDesc& s) {
  const TriMesh tm = read_mesh(s.mesh_path, s.mesh_where.empty() ? s.mesh_path : s.mesh_where);
  RenderMesh m;
  for (const Vec3d& v : tm.vertices)
    m.positions.push_back(to_f(v * s.mesh_scale + s.mesh_translate));
  m.triangles = tm.triangles;
  m.normals = vertex_normals(m.positions, m.triangles);
  return m;
}

RenderMesh posed(const RenderMesh& local, const RigidPose& pose) {
  RenderMesh m = local;
  const Eigen::Matrix3f R = pose.R.cast<float>();
  const Vec3f t = to_f(pose.t);
  for (Vec3f& p : m.positions) p = R * p + t;
  for (Vec3f& n : m.normals) n = R * n;
  return m;
}

double nice_tile(double radius) {
  return std::pow(10.0, std::floor(std::log10(std::max(radius, 1e-6))));
}

}  // namespace

Vec3d default_bulk_color(MaterialKind kind) {
  switch (kind) {
    case MaterialKind::Sand:
      return {0.76, 0.60, 0.38};
    case MaterialKind::Snow:
      return {0.92, 0.93, 0.96};
    case MaterialKind::Elastic:
      break;
  }
  return {0.36, 0.70, 0.30};
}

/// An axis-aligned box grown point by point: the framing box and the content bounds.
struct SceneAssembler::Bounds {
  Vec3d lo = Vec3d::Constant(1e300), hi = Vec3d::Constant(-1e300);
  bool empty() const { return (lo.array() > hi.array()).any(); }
  void add(const Vec3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void add(const std::vector<Vec3f>& points) {
    for (const Vec3f& p : points) add(p.cast<double>());
  }
  /// The 8 corners of box [blo, bhi] moved by pose.
  void add_box(const Vec3d& blo, const Vec3d& bhi, const RigidPose& pose) {
    for (int c = 0; c < 8; ++c)
      add(pose.apply(
          Vec3d(c & 1 ? bhi.x() : blo.x(), c & 2 ? bhi.y() : blo.y(), c & 4 ? bhi.z() : blo.z())));
  }
  /// Becomes [dlo, dhi] when empty.
  void or_else(const Vec3d& dlo, const Vec3d& dhi) {
    if (!empty()) return;
    lo = dlo;
    hi = dhi;
  }
};

SceneAssembler::SceneAssembler(const Scene& scene, std::string outdir, int framing_frame)
    : scene_(scene), outdir_(std::move(outdir)) {
  openvdb::initialize();
  choose_bulk();
  // Colliders, tessellated once in their own frame; the framing box.
  Bounds box;
  for (const SourceDesc& src : scene.sources) {
    if (src.shape.kind == ShapeDesc::Kind::Mesh) {
      box.add(shape_mesh_file(src.shape).positions);
    } else {
      const Aabb b = shape_bounds(src.shape);
      box.add_box(b.lo, b.hi, RigidPose());
    }
  }
  load_colliders(box);
  for (const ShellDesc& sh : scene.shells) {
    if (!sh.write_mesh) continue;
    try {
      box.add(read_shell(sh, framing_frame).positions);
    } catch (const CacheError&) {
      // framed without this shell
    }
  }
  set_frame(box);
  choose_camera();
}

void SceneAssembler::choose_bulk() {
  const RenderSettings& rs = scene_.render;
  const OutputSettings& out = scene_.output;
  const bool has_bulk = !scene_.sources.empty();
  // How the bulk material is drawn.
  // The reader refused a drawing whose cache the run does not write (io/scene_reader.cpp).
  bulk_ = rs.bulk;
  if (bulk_ == BulkDraw::Auto) {
    if (rs.renderer == RendererKind::Raytrace)
      bulk_ = out.density ? BulkDraw::Volume : out.particles ? BulkDraw::Particles : BulkDraw::None;
    else
      bulk_ = out.particles ? BulkDraw::Particles
              : out.density ? BulkDraw::Surface
                            : BulkDraw::None;
  }
  if (bulk_ == BulkDraw::Volume && rs.renderer == RendererKind::Raster) bulk_ = BulkDraw::Surface;
  if (!has_bulk) bulk_ = BulkDraw::None;
  SHELLMPM_CHECK((bulk_ != BulkDraw::Volume && bulk_ != BulkDraw::Surface) || out.density,
                 "render.bulk draws a density volume the run does not write");
  SHELLMPM_CHECK(bulk_ != BulkDraw::Particles || out.particles,
                 "render.bulk draws a particle cache the run does not write");
  if (has_bulk) {
    const SourceDesc& src = scene_.sources.front();
    const MaterialDesc& mat = scene_.materials[static_cast<std::size_t>(src.material)];
    bulk_color_ = to_f(mat.color ? *mat.color : default_bulk_color(mat.kind));
    particle_radius_ = static_cast<float>(
        rs.particle_radius.value_or(0.5 * scene_.shot.dx / std::cbrt(src.particles_per_cell)));
  }
}

void SceneAssembler::load_colliders(Bounds& box) {
  const RenderSettings& rs = scene_.render;
  for (std::size_t i = 0; i < scene_.colliders.size(); ++i) {
    const ColliderDesc& c = scene_.colliders[i];
    ColliderMesh cm;
    cm.keys = c.keyframes;
    std::vector<RigidPose> poses{keyframe_pose(c.keyframes, 0.0)};
    for (const Keyframe& k : c.keyframes) poses.push_back(keyframe_pose(c.keyframes, k.time));
    if (c.shape.kind == ShapeDesc::Kind::Plane) {
      const RigidPose p0 = poses.front();
      const Vec3d n = p0.R * c.shape.normal;
      if (rs.ground && ground_collider_ < 0 && n.y() > 0.7) {
        ground_collider_ = static_cast<int>(i);
        ground_point_ = p0.apply(c.shape.point);
        ground_normal_ = n.normalized();
      }
    } else {
      cm.local = c.shape.kind == ShapeDesc::Kind::Mesh ? shape_mesh_file(c.shape)
                                                       : tessellate_shape(c.shape);
      Bounds local;
      local.add(cm.local.positions);
      for (const RigidPose& p : poses) box.add_box(local.lo, local.hi, p);
    }
    cm.local.name = c.name;
    cm.local.kind = SurfaceKind::Collider;
    cm.local.front = cm.local.back = to_f(rs.collider_color);
    colliders_.push_back(std::move(cm));
  }
}

void SceneAssembler::set_frame(Bounds box) {
  const Vec3d dlo = scene_.shot.domain_min, dhi = scene_.shot.domain_max;
  box.or_else(dlo, dhi);
  box.lo = box.lo.cwiseMax(dlo);
  box.hi = box.hi.cwiseMin(dhi);
  box.or_else(dlo, dhi);
  has_ground_ = scene_.render.ground;
  if (has_ground_ && ground_collider_ < 0) {
    ground_point_ =
        Vec3d(0.5 * (box.lo.x() + box.hi.x()), box.lo.y(), 0.5 * (box.lo.z() + box.hi.z()));
    ground_normal_ = Vec3d(0, 1, 0);
  }
  if (has_ground_) {
    // Down to the ground under the box center, so contact with it is in the picture.
    const Vec3d c = 0.5 * (box.lo + box.hi);
    const double gy = ground_point_.y() - (ground_normal_.x() * (c.x() - ground_point_.x()) +
                                           ground_normal_.z() * (c.z() - ground_point_.z())) /
                                              ground_normal_.y();
    if (gy < box.lo.y()) box.lo.y() = std::max(gy, dlo.y());
  }
  frame_lo_ = box.lo;
  frame_hi_ = box.hi;
}

void SceneAssembler::choose_camera() {
  const RenderSettings& rs = scene_.render;
  std::string name = rs.camera;
  if (name.empty()) name = rs.cameras.empty() ? "auto" : rs.cameras.front().name;
  if (name == "auto") {
    camera_ = auto_frame(frame_lo_, frame_hi_, rs.width, rs.height);
  } else {
    auto it = std::find_if(rs.cameras.begin(), rs.cameras.end(),
                           [&](const RenderCamera& c) { return c.name == name; });
    SHELLMPM_CHECK(it != rs.cameras.end(), "render.camera '" << name << "' (the reader checks it)");
    camera_.eye = it->position;
    camera_.target = it->target;
    camera_.up_hint = it->up;
    camera_.fov_deg = it->fov_deg;
    camera_.width = rs.width;
    camera_.height = rs.height;
  }
  camera_.name = name;
}

std::string SceneAssembler::shell_path(const ShellDesc& sh, int frame) const {
  std::string pattern = scene_.output.shell_pattern;
  const auto at = pattern.find("{name}");
  if (at != std::string::npos) pattern.replace(at, 6, sh.name);
  return frame_path(outdir_, pattern, frame);
}

RenderMesh SceneAssembler::read_shell(const ShellDesc& sh, int frame) const {
  const std::string path = shell_path(sh, frame);
  RenderMesh m;
  m.name = sh.name;
  m.kind = SurfaceKind::Shell;
  if (scene_.output.shell_format == MeshFormat::Ply) {
    PlyMesh p = read_ply_cache(path);
    m.positions = std::move(p.positions);
    m.triangles = std::move(p.triangles);
    m.normals = std::move(p.normals);
  } else {
    require_cache_file(path);
    try {
      const TriMesh tm = read_mesh(path, path);
      for (const Vec3d& v : tm.vertices) m.positions.push_back(to_f(v));
      m.triangles = tm.triangles;
    } catch (const UserError& e) {
      throw CacheError(path, e.message);
    }
  }
  mesh_from_output_axes(m, mesh_file_up_axis(scene_.output.shell_format, scene_.output.up_axis));
  if (m.triangles.empty()) throw CacheError(path, "has no triangles");
  if (m.normals.size() != m.positions.size()) m.normals = vertex_normals(m.positions, m.triangles);
  for (Vec3f& n : m.normals) {
    const float l = n.norm();
    n = l > 0.0f ? Vec3f(n / l) : Vec3f(0, 1, 0);
  }
  const ShellMaterialDesc& mat = scene_.shell_materials[static_cast<std::size_t>(sh.material)];
  m.front = to_f(mat.front_color ? *mat.front_color : scene_.render.shell_front);
  m.back = to_f(mat.back_color ? *mat.back_color : scene_.render.shell_back);
  return m;
}

std::vector<std::string> SceneAssembler::files(int frame) const {
  std::vector<std::string> f;
  if (bulk_ == BulkDraw::Volume || bulk_ == BulkDraw::Surface)
    f.push_back(frame_path(outdir_, scene_.output.density_pattern, frame));
  if (bulk_ == BulkDraw::Particles)
    f.push_back(frame_path(outdir_, scene_.output.particles_pattern, frame));
  for (const ShellDesc& sh : scene_.shells)
    if (sh.write_mesh) f.push_back(shell_path(sh, frame));
  return f;
}

void SceneAssembler::add_mesh(PreviewScene& ps, Bounds& content, RenderMesh m) {
  if (m.kind != SurfaceKind::Ground) content.add(m.positions);
  ps.meshes.push_back(std::move(m));
}

void SceneAssembler::add_bulk(int frame, PreviewScene& ps, Bounds& content) const {
  const RenderSettings& rs = scene_.render;
  if (bulk_ == BulkDraw::Volume || bulk_ == BulkDraw::Surface) {
    const std::string path = frame_path(outdir_, scene_.output.density_pattern, frame);
    const openvdb::FloatGrid::Ptr grid = scalar_grid_from_output_axes<openvdb::FloatGrid>(
        read_density_grid(path), scene_.output.up_axis);
    if (bulk_ == BulkDraw::Surface) {
      RenderMesh m = iso_surface(*grid, rs.iso_value);
      m.front = m.back = bulk_color_;
      if (!m.triangles.empty()) add_mesh(ps, content, std::move(m));
    } else {
      ps.volume = dense_volume(*grid);
      ps.volume.extinction = static_cast<float>(rs.volume_extinction);
      ps.volume.color = bulk_color_;
      if (!ps.volume.empty()) {
        content.add(ps.volume.origin.cast<double>());
        content.add(
            (ps.volume.origin + (ps.volume.dims.cast<float>() - Vec3f::Ones()) * ps.volume.voxel)
                .cast<double>());
      }
    }
  } else if (bulk_ == BulkDraw::Particles) {
    const std::string path = frame_path(outdir_, scene_.output.particles_pattern, frame);
    ps.particles.positions = read_ply_cache(path).positions;
    points_from_output_axes(ps.particles.positions, scene_.output.up_axis);
    ps.particles.radius = particle_radius_;
    ps.particles.color = bulk_color_;
    content.add(ps.particles.positions);
    cull_hidden_particles(ps.particles);  // buried ones can neither be seen nor cast shadows
  }
}

void SceneAssembler::add_colliders(double t, const Vec3d& fc, double fr, PreviewScene& ps,
                                   Bounds& content) const {
  const Vec3d eye = camera_.eye;
  for (std::size_t i = 0; i < scene_.colliders.size(); ++i) {
    const ColliderDesc& c = scene_.colliders[i];
    const RigidPose pose = keyframe_pose(c.keyframes, t);
    if (c.shape.kind == ShapeDesc::Kind::Plane) {
      if (static_cast<int>(i) == ground_collider_) continue;
      const Vec3d n = (pose.R * c.shape.normal).normalized();
      const Vec3d p = pose.apply(c.shape.point);
      if (n.dot(eye - p) <= 0.0) continue;  // cut away: the camera looks through it
      const Vec3d center = fc - n * n.dot(fc - p);
      RenderMesh m = tessellate_square(center, n, 3.0 * fr, 8);
      m.name = c.name;
      m.kind = SurfaceKind::Collider;
      m.front = m.back = to_f(scene_.render.collider_color);
      ps.meshes.push_back(std::move(m));  // unbounded: not part of the shadow bounds
      continue;
    }
    add_mesh(ps, content, posed(colliders_[i].local, pose));
  }
}

void SceneAssembler::add_ground(double t, const Vec3d& fc, double fr, PreviewScene& ps) const {
  if (!has_ground_) return;
  Vec3d gp = ground_point_, gn = ground_normal_;
  if (ground_collider_ >= 0) {
    const ColliderDesc& c = scene_.colliders[static_cast<std::size_t>(ground_collider_)];
    const RigidPose pose = keyframe_pose(c.keyframes, t);
    gn = (pose.R * c.shape.normal).normalized();
    gp = pose.apply(c.shape.point);
  }
  const Vec3d center = fc - gn * gn.dot(fc - gp);
  const double half = 4.0 * fr;
  RenderMesh g = tessellate_square(center, gn, half, 16);
  g.name = "ground";
  g.kind = SurfaceKind::Ground;
  g.front = g.back = to_f(scene_.render.ground_color);
  ps.ground.center = to_f(center);
  ps.ground.radius = static_cast<float>(half);
  ps.ground.tile = static_cast<float>(nice_tile(fr));
  ps.meshes.push_back(std::move(g));
}

void SceneAssembler::add_lights(PreviewScene& ps) const {
  // A studio rig relative to the camera (or the scene's key direction).
  const Vec3d up(0, 1, 0);
  Vec3d back = camera_.eye - camera_.target;
  back.y() = 0.0;
  if (back.norm() < 1e-9) back = -camera_.up();  // looking straight down
  back.normalize();
  const Vec3d right = up.cross(back).normalized();
  const Vec3d key = scene_.render.key_light ? *scene_.render.key_light
                                            : (1.1 * up - 0.6 * right + 0.5 * back).normalized();
  ps.lights.key_dir = to_f(key.normalized());
  ps.lights.fill_dir = to_f((0.35 * up + 0.8 * right + 0.6 * back).normalized());
  ps.lights.key = 0.8f;
  ps.lights.fill = 0.25f;
  ps.lights.ambient = 0.3f;
}

PreviewScene SceneAssembler::assemble(int frame) const {
  const double t = (frame - 1) / scene_.shot.fps;
  PreviewScene ps;
  ps.samples = scene_.render.samples;
  ps.ao_samples = scene_.render.ao_samples;
  const Vec3d fc = 0.5 * (frame_lo_ + frame_hi_);
  const double fr = std::max(0.5 * (frame_hi_ - frame_lo_).norm(), 1e-3);
  Bounds content;
  // Shells first: a shell cache error is the most likely and cheapest to detect.
  for (const ShellDesc& sh : scene_.shells)
    if (sh.write_mesh) add_mesh(ps, content, read_shell(sh, frame));
  add_bulk(frame, ps, content);
  add_colliders(t, fc, fr, ps, content);  // at the frame's time
  add_ground(t, fc, fr, ps);
  add_lights(ps);
  content.or_else(frame_lo_, frame_hi_);
  ps.bounds_lo = to_f(content.lo);
  ps.bounds_hi = to_f(content.hi);
  ps.ao_distance = static_cast<float>(0.15 * fr);
  return ps;
}

}  // namespace shellmpm

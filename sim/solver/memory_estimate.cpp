#include "sim/solver/memory_estimate.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "sim/core/types.h"

namespace shellmpm {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double R = sizeof(Real);
constexpr double kVec3 = sizeof(Vec3), kMat3 = sizeof(Mat3);
constexpr double kVector = sizeof(std::vector<int>);  // one std::vector object

/// Bytes glibc's malloc takes for a small request of n bytes (16-byte chunks, 8 of header).
double chunk(double n) {
  return std::max(32.0, std::ceil((n + 8.0) / 16.0) * 16.0);
}

/// The capacity push_back growth leaves for n elements (a power of two).
double grown(double n) {
  return n < 1 ? 0 : std::exp2(std::ceil(std::log2(n)));
}

/// Lattice spacing of a source: dx / ppc^(1/3) (SourceSampler).
double spacing(const SourceDesc& src, const ShotSettings& shot) {
  return shot.dx / std::cbrt(src.particles_per_cell);
}

double shape_volume(const ShapeDesc& s) {
  switch (s.kind) {
    case ShapeDesc::Kind::Box:
      return (s.max - s.min).prod();
    case ShapeDesc::Kind::Sphere:
      return 4.0 / 3.0 * kPi * s.radius * s.radius * s.radius;
    case ShapeDesc::Kind::Cylinder:
      return kPi * s.radius * s.radius * s.height;
    case ShapeDesc::Kind::Mesh: {
      if (!s.sdf) return 0;
      double inside = 0;
      for (float v : s.sdf->values) inside += v < 0 ? 1.0 : 0.0;
      return inside * s.sdf->spacing * s.sdf->spacing * s.sdf->spacing;
    }
    case ShapeDesc::Kind::Plane:
      return 0;
  }
  return 0;
}

/// The shape's bounding box extents [m].
Vec3d shape_extent(const ShapeDesc& s) {
  switch (s.kind) {
    case ShapeDesc::Kind::Box:
      return s.max - s.min;
    case ShapeDesc::Kind::Sphere:
      return Vec3d::Constant(2 * s.radius);
    case ShapeDesc::Kind::Cylinder:
      return Vec3d::Constant(2 * s.radius + s.height);
    case ShapeDesc::Kind::Mesh:
      if (!s.sdf) return Vec3d::Zero();
      return s.sdf->spacing * (s.sdf->dims.cast<double>().array() - 1).matrix();
    case ShapeDesc::Kind::Plane:
      return Vec3d::Zero();
  }
  return Vec3d::Zero();
}

/// Area of the shape's shadow along the unit direction d [m^2].
double cross_section(const ShapeDesc& s, const Vec3d& d) {
  switch (s.kind) {
    case ShapeDesc::Kind::Box: {
      const Vec3d e = s.max - s.min;
      return std::abs(d.x()) * e.y() * e.z() + std::abs(d.y()) * e.x() * e.z() +
             std::abs(d.z()) * e.x() * e.y();
    }
    case ShapeDesc::Kind::Sphere:
      return kPi * s.radius * s.radius;
    case ShapeDesc::Kind::Cylinder: {
      const double c = std::min(1.0, std::abs(s.axis.dot(d)));
      return 2 * s.radius * s.height * std::sqrt(1 - c * c) + kPi * s.radius * s.radius * c;
    }
    case ShapeDesc::Kind::Mesh: {
      // The bounding box's shadow, shrunk by how much of the box the mesh fills.
      const Vec3d e = shape_extent(s);
      const double box = e.prod();
      const double fill = box > 0 ? std::min(1.0, shape_volume(s) / box) : 0;
      return std::pow(fill, 2.0 / 3.0) *
             (std::abs(d.x()) * e.y() * e.z() + std::abs(d.y()) * e.x() * e.z() +
              std::abs(d.z()) * e.x() * e.y());
    }
    case ShapeDesc::Kind::Plane:
      return 0;
  }
  return 0;
}

/// Occupied 4-cell blocks of a compact region of volume `vol` inside a box of `extent`, and
/// their grid blocks (each particle block and its +1 neighbours).
void solid_blocks(double vol, const Vec3d& extent, double dx, double& pblocks, double& gblocks) {
  const double b = 4 * dx;
  const double box = (extent.array() / b + 1.0).prod();  // blocks the bounding box touches
  const double fill = extent.prod() > 0 ? std::min(1.0, vol / extent.prod()) : 1.0;
  const double p = std::max(1.0, box * fill);
  const double a = std::cbrt(p);
  pblocks += p;
  gblocks += p * std::pow((a + 1) / a, 3);
}

/// One shell's control mesh counts, from closed forms for procedural geometry and from the
/// loaded mesh otherwise. support: mean control points per quadrature point (the Loop patch
/// of a triangle: 12 when its vertices are regular, N + 6 with one of valence N, fewer on
/// the boundary).
struct ShellCounts {
  double vertices = 0, triangles = 0, support = 12, area = 0;
  bool has_uvs = false;
};

ShellCounts shell_counts(const ShellDesc& d) {
  ShellCounts c;
  const double s2 = d.scale * d.scale;
  switch (d.kind) {
    case ShellDesc::Kind::Sheet: {
      const double nx = d.resolution[0], nz = d.resolution[1];
      c.vertices = (nx + 1) * (nz + 1);
      c.triangles = 2 * nx * nz;
      c.support = 12 - 5 * (1 / nx + 1 / nz);
      c.area = d.size[0] * d.size[1] * s2;
      c.has_uvs = true;
      break;
    }
    case ShellDesc::Kind::Cylinder: {
      const double na = d.resolution[0], nl = d.resolution[1];
      const bool closed = d.angle_deg == 360.0;
      c.vertices = (closed ? na : na + 1) * (nl + 1);
      c.triangles = 2 * na * nl;
      c.support = 12 - 5 * ((closed ? 0 : 1 / na) + 1 / nl);
      c.area = 2 * kPi * d.radius * d.angle_deg / 360.0 * d.height * s2;
      c.has_uvs = true;
      break;
    }
    case ShellDesc::Kind::Sphere: {
      const double f = std::exp2(2.0 * d.subdivisions);
      c.vertices = 10 * f + 2;
      c.triangles = 20 * f;
      c.support = 12 - 60 / c.triangles;  // 60 faces touch the 12 vertices of valence 5
      c.area = 4 * kPi * d.radius * d.radius * s2;
      break;
    }
    case ShellDesc::Kind::Mesh: {
      if (!d.mesh) break;
      const ShellMesh& m = *d.mesh;
      c.vertices = static_cast<double>(m.vertices.size());
      c.triangles = static_cast<double>(m.triangles.size());
      c.has_uvs = !m.uvs.empty();
      std::vector<int> faces(m.vertices.size(), 0);
      for (const Eigen::Vector3i& t : m.triangles)
        for (int k = 0; k < 3; ++k) ++faces[t[k]];
      double sum = 0, area = 0;
      for (const Eigen::Vector3i& t : m.triangles) {
        sum += std::max(6, faces[t[0]] + faces[t[1]] + faces[t[2]] - 6);
        area +=
            0.5 *
            (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]).norm();
      }
      c.support = c.triangles > 0 ? sum / c.triangles : 12;
      c.area = area * s2;
      break;
    }
  }
  return c;
}

/// Vertices and triangles of the limit mesh after `levels` of midpoint refinement
/// (E = V + T is Euler's count for a disc, close enough for a closed surface).
void refined(double v, double t, int levels, double& v_out, double& t_out) {
  double e = v + t;
  for (int l = 0; l < levels; ++l) {
    v += e;
    e = 2 * e + 3 * t;
    t *= 4;
  }
  v_out = v;
  t_out = t;
}

/// A LimitMesh of nv rows (each a BasisPoint's ctrl and n, d1, d2 in Real) and nt triangles.
double limit_mesh_bytes(double nv, double nt, double support, bool uvs) {
  const double cap = grown(support);
  const double row = 4 * kVector + chunk(4 * support) + 3 * chunk(R * cap);
  return nv * row + 12 * nt + (uvs ? 16 * nv : 0);
}

/// Grid arrays (SparseGrid) for `points` binned into pblocks / gblocks: per particle block
/// its key, neighbours, start, column place and runs of points (a few, 24 bytes each with
/// the binning's; the sources fill block by block), per grid
/// block its 4^3 nodes, key and sources; both hash tables at load <= 1/2 (the transfers
/// scatter through a thread's 6^3 buffer, colour by colour: no buffer per block). `order`:
/// the grid keeps the sort order (4 bytes a point: shells or the implicit solve); `nodes`:
/// the grid blocks have nodes (not the per-shell fields' binning grids).
double grid_bytes(double points, double pblocks, double gblocks, bool order, bool nodes = true) {
  constexpr double kNode = 4 * R;  // GridNode: m, v[3]
  const double hash = 16 * 3;      // 12 + 4 bytes a slot, 2 to 4 slots an entry
  return (order ? 4 : 0) * points + pblocks * (8 + 32 + 4 + 8 + 4 * 24 + hash) +
         gblocks * ((nodes ? 64 * kNode : 0) + 8 + 32 + hash);
}

/// What the shells hold and build, summed over the shells (estimate_solver_memory).
struct ShellTotals {
  double shells_persistent = 0, construction = 0, grid_points = 0;
  double contact_bytes = 0, integrity_bytes = 0, shell_bytes = 0, guard_bytes = 0;
  std::size_t grid_shells = 0;
  std::vector<double> shell_pblocks;  ///< particle blocks of each shell on the grid
};

/// Adds shell i of the scene to the totals and its counts to n.
void add_shell_memory(const Scene& scene, std::size_t i, MemoryCounts& n, ShellTotals& t) {
  const ShotSettings& shot = scene.shot;
  const double dx = shot.dx;
  const ShellDesc& d = scene.shells[i];
  const ShellMaterialDesc& m = scene.shell_materials[d.material];
  const ShellCounts c = shell_counts(d);
  const double V = c.vertices, T = c.triangles, S = c.support;
  const double qp = T * m.quadrature_inplane, entries = qp * S;
  const double layers = m.quadrature_thickness;
  double Vout = 0, Tout = 0;
  refined(V, T, d.output_refine, Vout, Tout);
  n.shell_points += V;
  n.largest_shell = std::max(n.largest_shell, V);
  n.shell_triangles += T;
  n.quadrature_points += qp;
  n.output_vertices += Vout;

  // ShellObject: state, Loop basis fans, Kirchhoff-Love data, the output limit mesh.
  const double object = V * (2 * kVec3 + R + 24 + 1 + 4) + 12 * T;
  const double basis = 12 * T + 8 * V + 12 * T + 12 * T + V;
  // Per entry its control point and gather slot (4 + 4), coefficients and value (6 R).
  // In float, the faces' patches (sim/shell/kl_patches.h): per (face, control point) its
  // control point and slot, per face its start, pattern and place in the order, per
  // control point its gather start (the patterns' tables are a few kB), and a copy of the
  // points' B and area in lanes.
  const bool patched = sizeof(Real) == 4;
  const double face_entries = T * S;
  const double patches =
      patched ? face_entries * 8 + T * 12 + 8 * V + qp * (4 * R * layers + R) : 0;
  const double kl = entries * (8 + 6 * R) + qp * (8 + R + 4 * R * layers + 4 * R) +
                    (m.yield_stress > 0 ? qp * 4 * R * layers : 0) + 8 * V + patches;
  const double limit = limit_mesh_bytes(Vout, Tout, S, c.has_uvs);
  // + the force buffer, and the Kirchhoff-Love force shares kept between steps (4 scalars
  // per entry, per face entry on patches).
  const double persistent =
      object + basis + kl + limit + V * kVec3 + 4 * R * (patched ? face_entries : entries);
  // While the Kirchhoff-Love data is built: every quadrature point's BasisPoint (seven
  // vectors grown by push_back), the weights and the rest mesh passed in.
  const double cap = grown(S);
  const double points = qp * (7 * kVector + chunk(4 * cap) + 6 * chunk(8 * cap)) + 8 * qp;
  const double rest_mesh = 24 * V + 12 * T + (c.has_uvs ? 16 * V : 0);
  t.construction =
      std::max(t.construction, t.shells_persistent + object + basis + kl + points + rest_mesh);
  t.shells_persistent += persistent;
  t.shell_bytes += persistent;

  if (!shell_contact_on(scene, i)) return;
  ++t.grid_shells;
  const double sites = T * m.contact_samples;
  n.contact_sites += sites;
  const double site_support = S;
  // (Per site: x, a3E, G3, volume, state, stencil and transposed stencil, G1 and G2 (in
  // eight floats) and the return mapping's tangents; per control point C, the transposed offsets
  // and the tangents' control points. A stencil's weights are shared by the sites that have the
  // same ones: all but about one site in ten, those at irregular vertices and borders.)
  t.contact_bytes += sites * (3 * kVec3 + R + 1 + 4 + 4 + site_support * (4 + 0.1 * 3 * R) +
                              site_support * (4 + 2 * R) + 8 * R + 2 * kVec3) +
                     V * (kMat3 + 4 + kVec3);
  // The integrity monitor's own limit mesh (level 0), edges, rim distances, positions.
  t.integrity_bytes += limit_mesh_bytes(V, T, S, false) + V * (8 + 48 + 3) + 1.5 * T * 8;
  // The shell guard (sim/contact/shell_guard.h): its own limit mesh, edges (1.5 T), rest
  // positions; per pass the control and limit positions, velocities and inverse masses
  // (double); the triangle and edge grids of a list build, each feature in about 4 cells
  // (a sorted (key, feature) pair plus the kept key and feature), and the stamps; the
  // pairs near at rest (measured on a regular sheet: 14 triangles per vertex, 12 edges
  // per edge, as ints, and an offset per vertex and per edge); the edges' boxes and first
  // cells (BoxPairs).
  if (shot.shell_guard)
    t.guard_bytes += limit_mesh_bytes(V, T, S, false) + 1.5 * T * 8 + V * (24 + 8) + V * 4 * 24 +
                     2.5 * T * 4 * (16 + 12) + 2.5 * T * 4 + V * (14 + 1.5 * 12) * 4 +
                     (V + 1.5 * T) * 8 + 1.5 * T * (48 + 8);
  // Shell table, binned positions, pin holds and the force buffer of the grid shell.
  t.grid_points += V;
  t.shell_bytes += V * (2 + 4 + kVec3 + 1 + kVec3);
  // Blocks: the surface covers area / (4 dx)^2 blocks, half again for folds and tilt; a
  // sheet's grid blocks are about twice its particle blocks (one layer each side).
  const double pb = std::max(1.0, 1.5 * c.area / (16 * dx * dx));
  t.shell_pblocks.push_back(pb);
  n.particle_blocks += pb;
  n.grid_blocks += 2.2 * pb;
}

}  // namespace

bool shell_contact_on(const Scene& scene, std::size_t i) {
  const bool others = !scene.colliders.empty() || !scene.sources.empty() || scene.shells.size() > 1;
  const ShellDesc::Contact mode = scene.shells[i].contact;
  return mode == ShellDesc::Contact::On || (mode == ShellDesc::Contact::Auto && others);
}

double expected_source_particles(const SourceDesc& src, const ShotSettings& shot) {
  const double h = spacing(src, shot);
  const double per_volume = 1.0 / (h * h * h);
  if (!src.emit) return shape_volume(src.shape) * per_volume;
  const double speed = src.velocity.norm();
  if (!(speed > 0)) return 0;
  const double duration = (src.emit_end - src.emit_start + 1) / shot.fps;
  return per_volume * cross_section(src.shape, src.velocity / speed) * speed * duration;
}

namespace {

/// Bulk particles and the blocks they occupy (at rest density; emitted material counted
/// as a loose pile, half full) into n.
void add_bulk_counts(const Scene& scene, MemoryCounts& n) {
  const ShotSettings& shot = scene.shot;
  const double dx = shot.dx;
  for (const SourceDesc& src : scene.sources) {
    const double count = expected_source_particles(src, shot);
    const double h = spacing(src, shot);
    if (src.emit) {
      n.emitted_particles += count;
      const double vol = 2 * count * h * h * h;
      solid_blocks(vol, Vec3d::Constant(std::cbrt(vol)), dx, n.particle_blocks, n.grid_blocks);
    } else {
      n.fill_particles += count;
      solid_blocks(shape_volume(src.shape), shape_extent(src.shape), dx, n.particle_blocks,
                   n.grid_blocks);
    }
  }
}

/// Per-shell velocity fields (shot.shell_velocities: per_shell) when two bodies share the
/// grid (two shells, a shell and bulk, or a shell's folds): each bins its control points
/// into its own grid and keeps 4^3 nodes of 16 Reals (a lone shell 3 more: mass and
/// height range; no buffers); the combined grid keeps the bulk moments. Fold blocks are
/// transient and few (a crumple's folds cover a fraction of its blocks). 0 when the fields
/// are off.
double fields_memory(const Scene& scene, const ShellTotals& t, const MemoryCounts& n) {
  const ShotSettings& shot = scene.shot;
  const std::size_t grid_shells = t.grid_shells;
  const bool fields_wanted = shot.shell_velocities == ShellVelocities::PerShell;
  const bool fields =
      fields_wanted &&
      (grid_shells >= 2 || (grid_shells >= 1 && (shot.fold_fields || !scene.sources.empty())));
  double fields_bytes = 0;
  if (!fields) return fields_bytes;
  // One shell without bulk also keeps mass and height range per node (heights only).
  const bool heights = grid_shells == 1 && scene.sources.empty();
  for (double pb : t.shell_pblocks) {
    const double gb = 2.2 * pb;
    fields_bytes +=
        grid_bytes(0, pb, gb, true, false) + gb * 64 * (16 * R + kVec3 + (heights ? 3 * R : 0));
  }
  fields_bytes += 24 * n.shell_points + n.particle_blocks * 216 * 4 * R +
                  n.grid_blocks * (64 * kVec3 + 64 * 4 * R + 4 * grid_shells + 1);
  return fields_bytes;
}

}  // namespace

SolverMemory estimate_solver_memory(const Scene& scene) {
  SolverMemory out;
  MemoryCounts& n = out.counts;
  bool plastic = false;
  for (const MaterialDesc& m : scene.materials)
    plastic = plastic || m.kind != MaterialKind::Elastic;
  const double per_particle = 2 * kVec3 + 2 * kMat3 + 2 + 4 + (plastic ? R : 0);
  out.bytes_per_particle = per_particle;
  add_bulk_counts(scene, n);
  ShellTotals t;
  for (std::size_t i = 0; i < scene.shells.size(); ++i) add_shell_memory(scene, i, n, t);
  const double fields_bytes = fields_memory(scene, t, n);

  // The particles at the peak, and the combined grid.
  const double particles = per_particle * n.peak_particles();
  const double grid =
      grid_bytes(n.peak_particles() + t.grid_points, n.particle_blocks, n.grid_blocks,
                 t.grid_shells > 0 || scene.shot.integrator == Integrator::Implicit);
  // The integrity monitor records a side per particle and limit vertex once shells are on
  // the grid.
  double integrity_bytes = t.integrity_bytes;
  if (t.grid_shells > 0) integrity_bytes += 3 * n.peak_particles();

  out.parts = {{"particles", particles},           {"grid", grid},
               {"shells", t.shell_bytes},          {"contact", t.contact_bytes},
               {"per-shell fields", fields_bytes}, {"integrity", integrity_bytes},
               {"shell guard", t.guard_bytes}};
  double held = 0;
  for (const MemoryPart& p : out.parts) held += p.bytes;
  // A step: an emitting run copies one particle attribute (a Mat3) when its arrays double.
  const double growth = n.emitted_particles > 0 ? kMat3 * n.peak_particles() : 0;
  // After each frame the particles are sorted by block in place, with a bit per particle
  // (sim/mpm/particles.cpp), through the sort order (4 bytes each, the grid's nodes freed
  // meanwhile).
  const double permute = 4.125 * n.peak_particles();
  // Contact and integrity scratch of a step (measured: about 200 bytes per contact site).
  const double contact_scratch = 200 * n.contact_sites;
  // The implicit grid solve (sim/implicit/grid_step.cpp): about 17 double vectors of 3 per
  // grid node (the objective's, Newton's and CG's) and two double buffers per particle block.
  const double implicit_grid =
      scene.shot.integrator == Integrator::Implicit
          ? n.grid_blocks * 64 * 17 * 24.0 + n.particle_blocks * 2 * 216 * 24.0
          : 0.0;
  // The implicit shell step (sim/implicit/shell_step.cpp), measured by peak RSS on one
  // clamped steel sheet of (n+1)^2 control points, n = 32, 64, 128 (2026-12-03): with the
  // block-Jacobi preconditioner about 24 kB per control point over an explicit run (the
  // double copy of the Kirchhoff-Love data, the finite-difference tangent, its triplets
  // and its symmetrised copy); the LDL^T factor adds 3.0, 7.1 and 13.4 kB per point, i.e.
  // about 105 V^1.5 bytes for a shell of V points (fill-in of a 2-D mesh under AMD
  // ordering grows with its width). Shells are stepped one at a time: the factor counts
  // once, for the largest.
  double implicit_shells = 0;
  if (scene.shot.integrator == Integrator::Implicit) {
    implicit_shells = 24e3 * n.shell_points;
    if (scene.shot.implicit_preconditioner == ImplicitPreconditioner::Factorised)
      implicit_shells += 105 * std::pow(n.largest_shell, 1.5);
  }
  out.held_bytes = held;
  out.step_scratch = std::max({contact_scratch + implicit_grid + implicit_shells, growth, permute});
  // Built: the shells one by one, then contact and integrity, then the fill particles
  // (every source's points in a vector of Vec3d, up to doubled by push_back, all held
  // while the particle arrays, allocated once at their final size, take them in).
  const double after_shells = t.shells_persistent + t.contact_bytes + integrity_bytes;
  const double fill = after_shells + per_particle * n.fill_particles + 2 * 24 * n.fill_particles;
  out.construction_bytes = std::max(t.construction, fill);
  return out;
}

}  // namespace shellmpm

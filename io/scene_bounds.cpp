#include "io/scene_bounds.h"

#include <cmath>
#include <sstream>

#include "io/mesh_reader.h"
#include "io/scene_reader.h"
#include "io/user_error.h"
#include "sim/collider/shape_sdf.h"
#include "sim/shell/shell_object.h"
#include "sim/solver/memory_estimate.h"
#include "sim/solver/source_sampler.h"

namespace shellmpm {
namespace {

std::string point_text(const Vec3d& p) {
  std::ostringstream os;
  os << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return os.str();
}

/// Whether p lies outside the box [lo, hi].
bool outside(const Vec3d& p, const Vec3d& lo, const Vec3d& hi) {
  return (p.array() < lo.array()).any() || (p.array() > hi.array()).any();
}

void check_sources(const Scene& scene) {
  const ShotSettings& s = scene.shot;
  // Particles must stay one cell inside the domain (the grid stencil needs it).
  const Vec3d lo = s.domain_min.array() + s.dx, hi = s.domain_max.array() - s.dx;
  for (std::size_t i = 0; i < scene.sources.size(); ++i) {
    const SourceDesc& src = scene.sources[i];
    const std::string where = src.shape.where.empty()
                                  ? scene.path + ": sources[" + std::to_string(i) + "].shape"
                                  : src.shape.where;
    const Aabb b = shape_bounds(src.shape);
    if (!outside(b.lo, lo, hi) && !outside(b.hi, lo, hi)) continue;
    Vec3d bad = outside(b.lo, lo, hi) ? b.lo : b.hi;
    bool found = src.emit;  // an emitter's shape itself must be inside
    if (!found) {
      // The bounds reach past the domain: a lattice point does too unless the shape is
      // rounded there. Beyond two lattice spacings (jitter included) a point surely does.
      const double h = s.dx / std::cbrt(src.particles_per_cell);
      const Vec3d far_lo = lo.array() - 2 * h, far_hi = hi.array() + 2 * h;
      found = outside(b.lo, far_lo, far_hi) || outside(b.hi, far_lo, far_hi);
      if (!found) {
        SourceSampler(src, s.dx, s.fps).fill([&](const Vec3d& p) {
          if (!found && outside(p, lo, hi)) {
            found = true;
            bad = p;
          }
        });
      }
    }
    if (found) {
      std::ostringstream os;
      os << "source reaches outside shot.domain (less one cell, dx = " << s.dx << "): e.g. "
         << point_text(bad) << "; enlarge the domain or move the source";
      throw detail::user_error_at(where, os.str());
    }
  }
}

void check_shells(const Scene& scene) {
  const ShotSettings& s = scene.shot;
  const double range = kPositionRangeCells * s.dx;
  for (std::size_t i = 0; i < scene.shells.size(); ++i) {
    const ShellDesc& sd = scene.shells[i];
    const std::string key = "shells[" + std::to_string(i) + "]";
    const std::string where =
        sd.placement_where.empty() ? scene.path + ": " + key + ".translate" : sd.placement_where;
    const ShellMesh rest = build_shell_rest_mesh(sd);
    const bool contact = shell_contact_on(scene, i);
    const Vec3d lo = contact ? Vec3d(s.domain_min.array() + s.dx) : Vec3d::Constant(-range);
    const Vec3d hi = contact ? Vec3d(s.domain_max.array() - s.dx) : Vec3d::Constant(range);
    double far = 0;
    for (const Vec3d& p : rest.vertices) {
      if (!p.allFinite() || outside(p, lo, hi)) {
        std::ostringstream os;
        os << "shell '" << sd.name << "' has a rest control point at " << point_text(p);
        if (contact)
          os << ", outside shot.domain less one cell (dx = " << s.dx
             << "; the shell has contact, so its points live on the grid)";
        else
          os << ", more than 2^17 cells of dx from the origin (" << range
             << " m), where float positions no longer resolve 1/64 of a cell";
        os << "; move it (translate), scale it down, or enlarge the domain";
        throw detail::user_error_at(where, os.str());
      }
      far = std::max(far, p.cwiseAbs().maxCoeff());
    }
    // The shortest edge against float's resolution at the shell's distance.
    double shortest = INFINITY;
    for (const Eigen::Vector3i& t : rest.triangles)
      for (int e = 0; e < 3; ++e)
        shortest = std::min(shortest, (rest.vertices[t[e]] - rest.vertices[t[(e + 1) % 3]]).norm());
    const double need = far * std::ldexp(1.0, -15);
    if (shortest < need) {
      std::ostringstream os;
      os << "shell '" << sd.name << "': its shortest rest edge, " << shortest
         << " m, spans fewer than 256 float steps at its distance " << far
         << " m from the origin (it needs >= " << need
         << " m there, or the strains are round-off); move the shell towards the origin, "
            "or use a coarser mesh (merge tiny edges)";
      throw detail::user_error_at(where, os.str());
    }
  }
}

void check_mesh_colliders(const Scene& scene) {
  const double range = kPositionRangeCells * scene.shot.dx;
  for (std::size_t i = 0; i < scene.colliders.size(); ++i) {
    const ShapeDesc& sh = scene.colliders[i].shape;
    if (sh.kind != ShapeDesc::Kind::Mesh || !sh.sdf) continue;
    const Aabb b = shape_bounds(sh);
    for (const Vec3d& p : {b.lo, b.hi}) {
      if (p.cwiseAbs().maxCoeff() <= range) continue;
      const std::string where = sh.mesh_where.empty()
                                    ? scene.path + ": colliders[" + std::to_string(i) + "].shape"
                                    : sh.mesh_where;
      std::ostringstream os;
      os << "the mesh collider reaches " << point_text(p)
         << " (after scale and translate), more than 2^17 cells of dx from the origin (" << range
         << " m), where float positions no longer resolve 1/64 of a cell";
      throw detail::user_error_at(where, os.str());
    }
  }
}

}  // namespace

void check_scene_bounds(const Scene& scene) {
  check_sources(scene);
  check_shells(scene);
  check_mesh_colliders(scene);
}

}  // namespace shellmpm

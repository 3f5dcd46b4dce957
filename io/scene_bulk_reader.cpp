// Reads materials, sources, colliders, their shapes and keyframes (io/scene_sections.h).
#include <cmath>

#include "io/number_text.h"
#include "io/scene_checks.h"
#include "io/scene_reader.h"
#include "io/scene_sections.h"
#include "sim/collider/shape_sdf.h"
#include "sim/core/check.h"

namespace shellmpm::scenefile {
namespace {

/// The stiffest the material gets: its P-wave modulus, hardened snow included. Past 1e14 Pa
/// (100x diamond) stresses times volumes and squared wave speeds near float's range; the key
/// named is the one that makes it large.
void check_stiffest_modulus(const MapReader& r, const MaterialDesc& m) {
  const double nu = m.poisson_ratio;
  const double ratio = (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
  const bool snow = m.kind == MaterialKind::Snow;
  const double harden = snow ? std::exp(m.hardening * m.critical_compression) : 1.0;
  const double modulus = m.youngs_modulus * ratio * harden;
  if (modulus <= 1e14) return;
  const std::string at = harden > ratio ? "hardening"
                         : ratio > 100  ? "poisson_ratio"
                                        : "youngs_modulus";
  fail(r.origin_of(at), r.path_of(at),
       "the material's stiffest modulus E (1 - nu) / ((1 + nu) (1 - 2 nu))" +
           std::string(snow ? " exp(hardening critical_compression)" : "") + " is " +
           fmt3(modulus) + " Pa (E " + fmt_num(m.youngs_modulus) + ", nu " + fmt_num(nu) +
           (snow ? ", hardening factor " + fmt_num(harden) : "") +
           "); at most 1e14 Pa, past any real solid");
}

ShapeDesc read_shape(const DocNode& node, const std::string& path, bool for_source,
                     const std::string& scene_path) {
  MapReader r(node, "shape", path, true);
  const std::string type = r.choice("type");
  if (for_source && type == "plane") {
    fail(r.origin_of("type"), r.path_of("type"),
         "a plane cannot be a source (use box, sphere, cylinder or mesh)");
  }
  r.check_keys(&type);
  ShapeDesc s;
  r.fill(s, &type);
  if (s.kind == ShapeDesc::Kind::Box)
    require_greater(s.min, s.max, r.origin_of("max"), r.path_of("max"));
  if (s.kind == ShapeDesc::Kind::Mesh) {
    std::tie(s.mesh_path, s.mesh_where) = read_mesh_path(r, "path", scene_path);
  }
  r.finish();
  return s;
}

/// The collider's shape within the position range (a mesh: once loaded, io/scene_bounds.h).
void check_collider_range(const MapReader& r, const ShapeDesc& shape, const ShotSettings& shot) {
  if (shape.kind == ShapeDesc::Kind::Plane) {
    require_in_position_range(shape.point, shot, r.origin_of("shape"),
                              r.path_of("shape") + ".point", "the plane's point");
  } else if (shape.kind != ShapeDesc::Kind::Mesh) {
    const Aabb b = shape_bounds(shape);
    for (const Vec3d& corner : {b.lo, b.hi})
      require_in_position_range(corner, shot, r.origin_of("shape"), r.path_of("shape"),
                                "the collider");
  }
}

}  // namespace

void read_materials(MapReader& top, Scene& scene) {
  NameSet names("material");
  top.each("materials", true, [&](MapReader& r, std::size_t) {
    MaterialDesc m;
    m.name = r.string("name");
    const std::string type = r.choice("type");
    r.check_keys(&type);
    r.fill(m, &type);
    names.add(m.name, r.path(), r.origin_of("name"), r.path_of("name"));
    check_stiffest_modulus(r, m);
    r.finish();
    scene.materials.push_back(std::move(m));
  });
}

void read_sources(MapReader& top, Scene& scene) {
  NameSet names("source");
  top.each("sources", false, [&](MapReader& r, std::size_t i) {
    SourceDesc src;
    src.name = name_or_default(r, "source", i);
    names.add(src.name, r.path(), r.origin_of("name"), r.path_of("name"));
    src.material = index_by_name(scene.materials, r.string("material"), "material", "materials",
                                 r.origin_of("material"), r.path_of("material"));
    src.shape = read_shape(*r.block("shape"), r.path_of("shape"), true, scene.path);
    src.shape.where = where_text(r.origin_of("shape"), r.path_of("shape"));
    r.fill(src);
    if (const DocNode* emit = r.block("emit")) {
      MapReader e(*emit, "sources[].emit", r.path_of("emit"), false);
      e.fill(src);
      e.finish();
      src.emit = true;
      if (src.velocity.isZero(0.0)) {
        fail(emit->origin, r.path_of("emit"),
             "continuous emission needs a nonzero velocity (" + r.path_of("velocity") +
                 " is [0, 0, 0])");
      }
    }
    r.finish();
    scene.sources.push_back(std::move(src));
  });
}

void read_colliders(MapReader& top, Scene& scene) {
  NameSet names("collider");
  top.each("colliders", false, [&](MapReader& r, std::size_t i) {
    ColliderDesc c;
    c.name = name_or_default(r, "collider", i);
    names.add(c.name, r.path(), r.origin_of("name"), r.path_of("name"));
    c.shape = read_shape(*r.block("shape"), r.path_of("shape"), false, scene.path);
    check_collider_range(r, c.shape, scene.shot);
    r.fill(c);
    c.keyframes = read_keyframes(r, "keyframes", scene.shot);
    r.finish();
    scene.colliders.push_back(std::move(c));
  });
}

std::vector<Keyframe> read_keyframes(MapReader& r, const std::string& key,
                                     const ShotSettings& shot) {
  std::vector<Keyframe> out;
  r.each(key, false, [&](MapReader& kr, std::size_t k) {
    const std::string& kp = kr.path();
    Keyframe kf;
    const bool has_time = kr.has("time"), has_frame = kr.has("frame");
    if (has_time && has_frame) {
      fail(kr.key_origin_of("frame"), kp, "give either time or frame, not both");
    }
    if (!has_time && !has_frame) fail(kr.origin(), kp, "needs a time (seconds) or a frame");
    // Frame N is the state written as frame N, at t = (N - 1) / fps (frame 1 = start).
    kf.time = has_time ? kr.number("time") : (kr.int32("frame") - 1) / shot.fps;
    const std::string tkey = has_time ? "time" : "frame";
    if (!out.empty() && !(kf.time > out.back().time)) {
      fail(kr.origin_of(tkey), kr.path_of(tkey),
           "keyframe times must strictly increase: " + fmt_num(kf.time) + " s is not after " +
               fmt_num(out.back().time) + " s (keyframe " + std::to_string(k - 1) + ")");
    }
    kr.fill(kf);
    require_in_position_range(kf.translate, shot, kr.origin_of("translate"),
                              kr.path_of("translate"), "the translation");
    kr.finish();
    out.push_back(kf);
  });
  return out;
}

}  // namespace shellmpm::scenefile

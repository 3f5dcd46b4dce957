// Reads shell materials and shells: geometry, placement, loads and pins
// (io/scene_sections.h).
#include <algorithm>

#include "io/number_text.h"
#include "io/scene_checks.h"
#include "io/scene_reader.h"
#include "io/scene_sections.h"
#include "sim/core/check.h"

namespace shellmpm::scenefile {
namespace {

/// Points per triangle: the in-plane rules the shell and contact samplers have.
void require_triangle_rule(const MapReader& r, const std::string& key, int n,
                           const std::string& what) {
  if (n == 1 || n == 3 || n == 6 || n == 7) return;
  fail(r.origin_of(key), r.path_of(key),
       "must be one of 1, 3, 6, 7 (" + what + " per triangle), got " + std::to_string(n));
}

/// Reads the `geometry` block of a shell into `sh`; returns the number of control points of
/// procedural geometry, or -1 for a mesh file (not known before it is loaded).
long long read_shell_geometry(MapReader& shell, ShellDesc& sh, const std::string& scene_path,
                              std::string& type) {
  MapReader g(*shell.block("geometry"), "shells[].geometry", shell.path_of("geometry"), true);
  type = g.choice("type");
  g.check_keys(&type);
  g.fill(sh, &type);
  long long n = -1;
  const std::array<int, 2>& res = sh.resolution;
  if (sh.kind == ShellDesc::Kind::Sheet) {
    n = (res[0] + 1LL) * (res[1] + 1LL);
  } else if (sh.kind == ShellDesc::Kind::Cylinder) {
    const bool closed = sh.angle_deg == 360.0;
    if (closed && res[0] < 3) {
      const DocNode* v = g.present("resolution");
      const Origin& o = v && v->kind == DocNode::Kind::List && v->items.size() == 2
                            ? v->items[0].origin
                            : g.origin_of("resolution");
      fail(o, g.path_of("resolution") + "[0]",
           "a closed cylinder (angle 360) needs at least 3 segments around, got " +
               std::to_string(res[0]));
    }
    n = closed ? res[0] * (res[1] + 1LL) : (res[0] + 1LL) * (res[1] + 1LL);
  } else if (sh.kind == ShellDesc::Kind::Sphere) {
    n = 10LL * (1LL << (2 * sh.subdivisions)) + 2;
  } else {
    std::tie(sh.mesh_path, sh.mesh_where) = read_mesh_path(g, "path", scene_path);
  }
  g.finish();
  return n;
}

/// The placed procedural mesh stays finite and near the domain (meshes from files are
/// checked once loaded: io/scene_bounds.h); a shell thicker than its radius has inverted
/// layers.
void check_shell_placement(const MapReader& r, const ShellDesc& sh, const Scene& scene) {
  const double range = kPositionRangeCells * scene.shot.dx;
  const double extent = sh.kind == ShellDesc::Kind::Sheet  ? std::max(sh.size[0], sh.size[1])
                        : sh.kind == ShellDesc::Kind::Mesh ? 0.0
                                                           : std::max(sh.radius, sh.height);
  if (!(sh.scale * extent <= 2.0 * range)) {
    fail(r.origin_of("geometry"), r.path_of("geometry"),
         "the shell is " + fmt_num(sh.scale * extent) + " m across (with scale " +
             fmt_num(sh.scale) + "), more than 2^18 cells of dx = " + fmt_num(scene.shot.dx) +
             " m; it cannot fit in the position range");
  }
  const ShellMaterialDesc& mat = scene.shell_materials[sh.material];
  const bool curved = sh.kind == ShellDesc::Kind::Sphere || sh.kind == ShellDesc::Kind::Cylinder;
  if (curved && !(mat.thickness < sh.scale * sh.radius)) {
    const DocNode* g = r.present("geometry");
    const DocNode* rad = g && g->kind == DocNode::Kind::Map ? find_entry(*g, "radius") : nullptr;
    fail(rad ? rad->origin : r.origin_of("geometry"), r.path_of("geometry") + ".radius",
         "the shell's radius " + fmt_num(sh.scale * sh.radius) + " m (after scale) is not " +
             "larger than the thickness " + fmt_num(mat.thickness) + " m of shell material '" +
             mat.name +
             "': its inner layers would pass through the axis (a thin shell is much thinner "
             "than its radius)");
  }
}

/// The pin's selector: exactly one of indices, box, group.
void read_pin_selector(MapReader& r, PinDesc& pin, const std::string& geometry_type,
                       const std::string& geometry_path, long long num_vertices) {
  std::vector<std::string> given;
  for (const char* sel : {"indices", "box", "group"})
    if (r.has(sel)) given.emplace_back(sel);
  if (given.empty()) {
    fail(r.origin(), r.path(), "needs exactly one of indices, box, group (none given)");
  }
  if (given.size() > 1) {
    fail(r.key_origin_of(given[1]), r.path_of(given[1]),
         "give exactly one of indices, box, group (both " + given[0] + " and " + given[1] +
             " are given)");
  }
  const std::string& sel = given[0];
  pin.where = where_text(r.origin_of(sel), r.path_of(sel));
  if (sel == "indices") {
    pin.indices = r.int_list("indices");
    if (num_vertices < 0) return;
    const DocNode& list = *r.present("indices");
    for (std::size_t k = 0; k < pin.indices.size(); ++k) {
      if (pin.indices[k] >= num_vertices) {
        fail(list.items[k].origin, r.path_of("indices") + "[" + std::to_string(k) + "]",
             index_range_message(pin.indices[k], num_vertices, "the " + geometry_type));
      }
    }
  } else if (sel == "box") {
    MapReader b(*r.block("box"), "shells[].pins[].box", r.path_of("box"), false);
    pin.has_box = true;
    b.fill(pin);
    for (int a = 0; a < 3; ++a) {
      if (!(pin.box_max[a] >= pin.box_min[a])) {
        fail(b.origin_of("max"), b.path_of("max"),
             std::string("must be >= min on every axis, but on ") + kAxis[a] +
                 " max = " + fmt_num(pin.box_max[a]) + " < min = " + fmt_num(pin.box_min[a]));
      }
    }
    b.finish();
  } else {
    pin.group = r.string("group");
    if (geometry_type != "mesh") {
      fail(r.origin_of("group"), r.path_of("group"),
           "vertex groups come from a mesh file; " + geometry_path + ".type is " + geometry_type +
               " (select by indices or box instead)");
    }
  }
}

PinDesc read_pin(MapReader& r, const std::string& geometry_type, const std::string& geometry_path,
                 long long num_vertices, const ShotSettings& shot) {
  PinDesc pin;
  read_pin_selector(r, pin, geometry_type, geometry_path, num_vertices);
  r.fill(pin);
  if (!pin.components[0] && !pin.components[1] && !pin.components[2]) {
    fail(r.origin_of("components"), r.path_of("components"),
         "at least one of x, y, z must be true (held); all false pins nothing");
  }
  pin.keyframes = read_keyframes(r, "keyframes", shot);
  r.finish();
  return pin;
}

std::vector<PointLoadDesc> read_point_loads(MapReader& r, long long num_vertices,
                                            const std::string& geometry_type) {
  std::vector<PointLoadDesc> out;
  r.each("point_loads", false, [&](MapReader& lr, std::size_t) {
    PointLoadDesc load;
    lr.fill(load);
    load.where = where_text(lr.origin_of("index"), lr.path_of("index"));
    if (num_vertices >= 0 && load.index >= num_vertices) {
      fail(lr.origin_of("index"), lr.path_of("index"),
           index_range_message(load.index, num_vertices, "the " + geometry_type));
    }
    lr.finish();
    out.push_back(load);
  });
  return out;
}

ShellDesc read_shell(MapReader& r, std::size_t i, const Scene& scene, NameSet& names) {
  ShellDesc sh;
  sh.name = name_or_default(r, "shell", i);
  if (!file_name_safe(sh.name)) {
    fail(r.origin_of("name"), r.path_of("name"),
         "shell name '" + sh.name +
             "' may hold only letters, digits, '_' and '-' (it is used in output file names)");
  }
  names.add(sh.name, r.path(), r.origin_of("name"), r.path_of("name"));
  sh.material = index_by_name(scene.shell_materials, r.string("material"), "shell material",
                              "shell_materials", r.origin_of("material"), r.path_of("material"));
  std::string type;
  const long long n = read_shell_geometry(r, sh, scene.path, type);
  r.fill(sh);
  require_in_position_range(sh.translate, scene.shot, r.origin_of("translate"),
                            r.path_of("translate"), "the translation");
  sh.placement_where = where_text(r.origin_of("translate"), r.path_of("translate"));
  check_shell_placement(r, sh, scene);
  sh.point_loads = read_point_loads(r, n, type);
  r.each("pins", false, [&](MapReader& pr, std::size_t) {
    sh.pins.push_back(read_pin(pr, type, r.path_of("geometry"), n, scene.shot));
  });
  r.finish();
  return sh;
}

}  // namespace

void read_shell_materials(MapReader& top, Scene& scene) {
  NameSet names("shell material");
  top.each("shell_materials", false, [&](MapReader& r, std::size_t) {
    ShellMaterialDesc m;
    r.fill(m);
    require_triangle_rule(r, "quadrature_inplane", m.quadrature_inplane, "points");
    require_triangle_rule(r, "contact_samples", m.contact_samples, "contact particles");
    names.add(m.name, r.path(), r.origin_of("name"), r.path_of("name"));
    r.finish();
    scene.shell_materials.push_back(std::move(m));
  });
}

void read_shells(MapReader& top, Scene& scene) {
  NameSet names("shell");
  top.each("shells", false, [&](MapReader& r, std::size_t i) {
    scene.shells.push_back(read_shell(r, i, scene, names));
  });
}

}  // namespace shellmpm::scenefile

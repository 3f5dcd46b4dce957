// Scene file reader: YAML/JSON -> a private document tree (values keep their file and line,
// or the --set override they came from) -> overrides applied -> validated into a Scene.
// Every key is looked up in scene_schema(); types, defaults and numeric ranges are checked
// from the schema itself, so the schema, the reader and docs/scene-format.md cannot drift.
#include "io/scene_reader.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "io/utf8.h"
#include "io/yaml_key_near.h"
#include "sim/collider/shape_sdf.h"
#include "sim/core/check.h"

namespace shellmpm {
namespace {

namespace fs = std::filesystem;

// ------------------------------------------------------------------------------------------
// Schema
// ------------------------------------------------------------------------------------------

/// Builder for one KeySpec, so the schema table below reads like the documentation.
class Spec {
 public:
  Spec(std::string key, KeyType type) {
    k_.key = std::move(key);
    k_.type = type;
  }
  Spec& required() {
    k_.presence = Presence::Required;
    return *this;
  }
  Spec& def(std::string yaml) {
    k_.presence = Presence::Default;
    k_.default_value = std::move(yaml);
    return *this;
  }
  Spec& optional(std::string prose) {
    k_.presence = Presence::Optional;
    k_.default_value = std::move(prose);
    return *this;
  }
  Spec& unit(std::string u) {
    k_.unit = std::move(u);
    return *this;
  }
  Spec& gt(double v) { return lower(v, true); }
  Spec& ge(double v) { return lower(v, false); }
  Spec& lt(double v) { return upper(v, true); }
  Spec& le(double v) { return upper(v, false); }
  Spec& choices(std::vector<std::string> c) {
    k_.choices = std::move(c);
    return *this;
  }
  Spec& only_for(std::vector<std::string> types) {
    k_.only_for = std::move(types);
    return *this;
  }
  Spec& nonempty() {
    k_.nonempty = true;
    return *this;
  }
  Spec& unit_vector() {
    k_.unit_vector = true;
    return *this;
  }
  Spec& rule(std::string r) {
    k_.rule = std::move(r);
    return *this;
  }
  operator KeySpec() const { return k_; }  // NOLINT: implicit by design (table syntax)

 private:
  Spec& lower(double v, bool open) {
    k_.min = v;
    k_.min_open = open;
    return *this;
  }
  Spec& upper(double v, bool open) {
    k_.max = v;
    k_.max_open = open;
    return *this;
  }
  KeySpec k_;
};

using T = KeyType;

/// The keys of one keyframe list item under `prefix` ("colliders[].keyframes[]").
/// Position keys that place simulated things off the grid (keyframes, collider shapes): within
/// the range where Real resolves 1/64 of a cell (see position_range()).
/// Output file names (patterns, stats): inside output.directory.
const char* const kOutputFile = "a relative file name; its folders are created";
const char* const kInPositionRange = "each coordinate within 2^17 dx of the origin";

std::vector<KeySpec> keyframe_specs(const std::string& prefix) {
  return {
      Spec(prefix + ".time", T::Number).optional("give time or frame").unit("s").ge(0),
      Spec(prefix + ".frame", T::Int).optional("give time or frame").ge(1),
      Spec(prefix + ".translate", T::Vec3).def("[0, 0, 0]").unit("m").rule(kInPositionRange),
      Spec(prefix + ".rotate", T::Vec3).def("[0, 0, 0]").unit("deg"),
  };
}

std::vector<KeySpec> build_schema() {
  const std::vector<std::string> kShapeTypes = {"plane", "box", "sphere", "cylinder", "mesh"};
  std::vector<KeySpec> schema;
  auto add = [&schema](std::vector<KeySpec> specs) {
    schema.insert(schema.end(), specs.begin(), specs.end());
  };
  const std::string kPinSelector = "give exactly one of indices, box, group";
  const std::string kColorRule = "linear RGB, each in [0, 1]";
  const std::string kStiffestModulus =
      "P-wave modulus E (1 - nu) / ((1 + nu) (1 - 2 nu)), times the largest snow hardening "
      "exp(hardening critical_compression), <= 1e14 Pa";
  add({
      // top level
      Spec("version", T::Int).required().ge(1).le(1),
      Spec("shot", T::Map).required(),
      Spec("materials", T::List).def("[]"),
      Spec("sources", T::List).def("[]"),
      Spec("colliders", T::List).def("[]"),
      Spec("shell_materials", T::List).def("[]"),
      Spec("shells", T::List).def("[]"),
      Spec("preroll", T::Map).def("{}"),
      Spec("output", T::Map).def("{}"),
      Spec("render", T::Map).def("{}"),
      // shot
      Spec("shot.frames", T::FrameRange).def("[1, 48]").ge(1).le(999999999),  // = kMaxFrameNumber
      Spec("shot.fps", T::Number).def("24").unit("1/s").ge(0.01).le(1e5),
      Spec("shot.cfl", T::Number).def("0.3").gt(0).le(1),
      Spec("shot.dt_min", T::Number)
          .def("1e-6")
          .unit("s")
          .ge(1e-9)
          .rule("1 / (fps dt_min) <= 1e7 (steps a frame may take)"),
      Spec("shot.dt_max", T::Number).def("1e-2").unit("s").gt(0).rule(">= dt_min"),
      Spec("shot.gravity", T::Vec3).def("[0, -9.81, 0]").unit("m/s^2").ge(-1e4).le(1e4),
      Spec("shot.domain", T::Map).required(),
      Spec("shot.domain.min", T::Vec3).required().unit("m").rule(kInPositionRange),
      Spec("shot.domain.max", T::Vec3)
          .required()
          .unit("m")
          .rule(std::string("> min on every axis; ") + kInPositionRange),
      Spec("shot.dx", T::Number)
          .required()
          .unit("m")
          .ge(1e-6)
          .le(1e3)
          .rule("at most 2^20 cells per axis"),
      Spec("shot.threads", T::Int).def("0").ge(0),
      Spec("shot.transfer", T::Enum).def("apic").choices({"apic", "mls"}),
      Spec("shot.shell_velocities", T::Enum).def("per_shell").choices({"per_shell", "shared"}),
      Spec("shot.fold_fields", T::Bool).def("true"),
      Spec("shot.shell_guard", T::Bool).def("true"),
      Spec("shot.shell_guard_gap", T::Number)
          .def("0")
          .unit("m")
          .ge(0)
          .le(1e3)
          .rule("0: the larger of 0.05 dx and the thickest contact shell"),
      Spec("shot.units", T::String).def("m").nonempty(),
      Spec("shot.on_integrity_failure", T::Enum).def("warn").choices({"warn", "stop"}),
      // materials
      Spec("materials[].name", T::String).required().nonempty().rule("unique"),
      Spec("materials[].type", T::Enum).required().choices({"elastic", "sand", "snow"}),
      Spec("materials[].model", T::Enum)
          .def("fixed_corotated")
          .choices({"fixed_corotated", "neo_hookean"})
          .only_for({"elastic"}),
      Spec("materials[].youngs_modulus", T::Number).def("1e5").unit("Pa").ge(1).le(1e12),
      Spec("materials[].poisson_ratio", T::Number).def("0.3").ge(0).lt(0.5).rule(kStiffestModulus),
      Spec("materials[].density", T::Number).def("1000").unit("kg/m^3").ge(0.1).le(1e5),
      Spec("materials[].friction_angle", T::Number)
          .def("30")
          .unit("deg")
          .ge(0)
          .lt(90)
          .only_for({"sand"}),
      Spec("materials[].cohesion", T::Number).def("0").ge(0).le(1).only_for({"sand"}),
      Spec("materials[].critical_compression", T::Number)
          .def("0.025")
          .gt(0)
          .lt(1)
          .only_for({"snow"}),
      Spec("materials[].critical_stretch", T::Number).def("0.0075").gt(0).le(1).only_for({"snow"}),
      Spec("materials[].hardening", T::Number).def("10").ge(0).le(100).only_for({"snow"}),
      Spec("materials[].color", T::Vec3)
          .optional("by type: elastic green, sand tan, snow white")
          .rule(kColorRule),
      // sources
      Spec("sources[].name", T::String)
          .optional("`source<i>` (i = list index)")
          .nonempty()
          .rule("unique"),
      Spec("sources[].material", T::String).required().rule("a name in materials"),
      Spec("sources[].shape", T::Shape)
          .required()
          .rule("not a plane; inside shot.domain, one cell in"),
      Spec("sources[].particles_per_cell", T::Number).def("8").ge(1).le(64),
      Spec("sources[].velocity", T::Vec3).def("[0, 0, 0]").unit("m/s").ge(-1e5).le(1e5),
      Spec("sources[].seed", T::Int).def("1").ge(0).le(4294967295.0),
      Spec("sources[].emit", T::Map)
          .optional("none: fill once at the start")
          .rule("velocity must be nonzero"),
      Spec("sources[].emit.frames", T::FrameRange).required().ge(1).le(999999999),
      // colliders
      Spec("colliders[].name", T::String)
          .optional("`collider<i>` (i = list index)")
          .nonempty()
          .rule("unique"),
      Spec("colliders[].shape", T::Shape)
          .required()
          .rule("its bounds (a plane: its point) within 2^17 dx of the origin"),
      Spec("colliders[].boundary", T::Enum).def("separate").choices({"sticky", "slip", "separate"}),
      Spec("colliders[].friction", T::Number).def("0").ge(0).le(10),
      Spec("colliders[].keyframes", T::List).def("[]").rule("times strictly increase"),
  });
  add(keyframe_specs("colliders[].keyframes[]"));
  add({
      // shell materials
      Spec("shell_materials[].name", T::String).required().nonempty().rule("unique"),
      Spec("shell_materials[].youngs_modulus", T::Number).def("1e6").unit("Pa").ge(1).le(1e12),
      Spec("shell_materials[].poisson_ratio", T::Number).def("0.3").ge(0).lt(0.5),
      Spec("shell_materials[].density", T::Number).def("1000").unit("kg/m^3").ge(0.1).le(1e5),
      Spec("shell_materials[].thickness", T::Number)
          .def("0.001")
          .unit("m")
          .ge(1e-7)
          .le(1)
          .rule("< the radius of a sphere or cylinder shell"),
      Spec("shell_materials[].yield_stress", T::Number).def("0").unit("Pa").ge(0).le(1e12),
      Spec("shell_materials[].stretch_limit", T::Number).def("1.5").gt(1).le(1.9),
      Spec("shell_materials[].damping", T::Number).def("0").unit("1/s").ge(0).le(1e4),
      Spec("shell_materials[].stiffness_damping", T::Number).def("0").unit("s").ge(0).le(1),
      Spec("shell_materials[].quadrature_inplane", T::Int).def("3").rule("one of: 1, 3, 6, 7"),
      Spec("shell_materials[].quadrature_thickness", T::Int).def("3").ge(1).le(5),
      Spec("shell_materials[].friction", T::Number).def("0.3").ge(0).le(10),
      Spec("shell_materials[].contact_stiffness", T::Number)
          .optional("`youngs_modulus`")
          .unit("Pa")
          .gt(0)
          .le(1e12),
      Spec("shell_materials[].contact_shear", T::Number)
          .optional("`contact_stiffness`")
          .unit("Pa")
          .gt(0)
          .le(1e12),
      Spec("shell_materials[].contact_samples", T::Int).def("1").rule("one of: 1, 3, 6, 7"),
      Spec("shell_materials[].front_color", T::Vec3)
          .optional("`render.shell_front`")
          .rule(kColorRule),
      Spec("shell_materials[].back_color", T::Vec3)
          .optional("`render.shell_back`")
          .rule(kColorRule),
      // shells
      Spec("shells[].name", T::String)
          .optional("`shell<i>` (i = list index)")
          .nonempty()
          .rule("unique; letters, digits, `_`, `-` only"),
      Spec("shells[].material", T::String).required().rule("a name in shell_materials"),
      Spec("shells[].geometry", T::Map).required(),
      Spec("shells[].scale", T::Number).def("1").ge(1e-6).le(1e6),
      Spec("shells[].rotate", T::Vec3).def("[0, 0, 0]").unit("deg"),
      Spec("shells[].translate", T::Vec3)
          .def("[0, 0, 0]")
          .unit("m")
          .rule("the rest mesh inside shot.domain (one cell in with contact)"),
      Spec("shells[].velocity", T::Vec3).def("[0, 0, 0]").unit("m/s").ge(-1e5).le(1e5),
      Spec("shells[].pressure", T::Number).def("0").unit("Pa").ge(-1e12).le(1e12),
      Spec("shells[].point_loads", T::List).def("[]"),
      Spec("shells[].point_loads[].index", T::Int).required().ge(0).rule("< number of vertices"),
      Spec("shells[].point_loads[].force", T::Vec3).required().unit("N").ge(-1e12).le(1e12),
      Spec("shells[].pins", T::List).def("[]"),
      Spec("shells[].pins[].indices", T::IntList)
          .optional(kPinSelector)
          .ge(0)
          .rule("non-empty; each < number of vertices"),
      Spec("shells[].pins[].box", T::Map).optional(kPinSelector),
      Spec("shells[].pins[].box.min", T::Vec3).required().unit("m"),
      Spec("shells[].pins[].box.max", T::Vec3).required().unit("m").rule(">= min on every axis"),
      Spec("shells[].pins[].group", T::String)
          .optional(kPinSelector)
          .nonempty()
          .rule("geometry type mesh only"),
      Spec("shells[].pins[].components", T::Bool3)
          .def("[true, true, true]")
          .rule("at least one true"),
      Spec("shells[].pins[].keyframes", T::List).def("[]").rule("times strictly increase"),
      Spec("shells[].pins[].release", T::Number).optional("never").unit("s").ge(0),
  });
  add(keyframe_specs("shells[].pins[].keyframes[]"));
  add({
      Spec("shells[].output_refine", T::Int).def("0").ge(0).le(4),
      Spec("shells[].write_mesh", T::Bool).def("true"),
      Spec("shells[].contact", T::Enum).def("auto").choices({"auto", "on", "off"}),
      // shell geometry (the value of shells[].geometry)
      Spec("shells[].geometry.type", T::Enum)
          .required()
          .choices({"sheet", "cylinder", "sphere", "mesh"}),
      Spec("shells[].geometry.size", T::Vec2).def("[1, 1]").unit("m").gt(0).only_for({"sheet"}),
      Spec("shells[].geometry.resolution", T::Int2)
          .def("[10, 10]")
          .ge(1)
          .le(2000)
          .only_for({"sheet", "cylinder"})
          .rule("closed cylinder: first >= 3"),
      Spec("shells[].geometry.radius", T::Number)
          .def("0.5")
          .unit("m")
          .gt(0)
          .only_for({"cylinder", "sphere"}),
      Spec("shells[].geometry.height", T::Number).def("1").unit("m").gt(0).only_for({"cylinder"}),
      Spec("shells[].geometry.angle", T::Number)
          .def("360")
          .unit("deg")
          .gt(0)
          .le(360)
          .only_for({"cylinder"}),
      Spec("shells[].geometry.subdivisions", T::Int).def("2").ge(0).le(7).only_for({"sphere"}),
      Spec("shells[].geometry.path", T::String)
          .required()
          .nonempty()
          .only_for({"mesh"})
          .rule("readable file; relative to the scene file"),
      // pre-roll
      Spec("preroll.enabled", T::Bool).def("false"),
      Spec("preroll.method", T::Enum).def("static").choices({"static", "dynamic"}),
      Spec("preroll.tolerance", T::Number).def("1e-4").gt(0),
      Spec("preroll.max_steps", T::Int).def("200000").ge(1),
      // output
      Spec("output.directory", T::String).def("out").nonempty(),
      Spec("output.density", T::Bool).def("true"),
      Spec("output.density_pattern", T::String)
          .def("density.####.vdb")
          .rule(std::string("exactly one run of `#`; ") + kOutputFile),
      Spec("output.velocity", T::Bool).def("false"),
      Spec("output.half_float", T::Bool).def("false"),
      Spec("output.voxel_size", T::Number).def("0").unit("m").ge(0).rule("0 or in [dx/8, 16 dx]"),
      Spec("output.particles", T::Bool).def("false"),
      Spec("output.particles_pattern", T::String)
          .def("particles.####.ply")
          .rule(std::string("exactly one run of `#`; ") + kOutputFile),
      Spec("output.stats", T::String).def("stats.json").nonempty().rule(kOutputFile),
      Spec("output.checkpoint_every", T::Int).def("0").ge(0),
      Spec("output.shell_pattern", T::String)
          .optional("`\"{name}.####.ply\"`, `.obj` or `.glb` as `shell_format` says")
          .rule(std::string("exactly one run of `#`; contains `{name}` when there are several "
                            "shells; ends in `.ply`, `.obj` or `.glb` as `shell_format` says; ") +
                kOutputFile),
      Spec("output.shell_format", T::Enum).def("ply").choices({"ply", "obj", "glb"}),
      // render (previews; nothing here changes the simulation)
      Spec("render.preview", T::Bool).def("false"),
      Spec("render.renderer", T::Enum).def("raster").choices({"raster", "raytrace"}),
      Spec("render.size", T::Int2).def("[960, 540]").ge(16).le(8192),
      Spec("render.camera", T::String)
          .optional("the first of `cameras`, else `auto`")
          .nonempty()
          .rule("`auto` or a name in cameras"),
      Spec("render.cameras", T::List).def("[]"),
      Spec("render.cameras[].name", T::String).required().nonempty().rule("unique; not `auto`"),
      Spec("render.cameras[].position", T::Vec3).required().unit("m"),
      Spec("render.cameras[].target", T::Vec3).required().unit("m").rule("not at position"),
      Spec("render.cameras[].up", T::Vec3)
          .def("[0, 1, 0]")
          .unit_vector()
          .rule("not along the view direction"),
      Spec("render.cameras[].fov", T::Number).def("40").unit("deg").gt(0).lt(180),
      Spec("render.samples", T::Int).def("4").ge(1).le(256),
      Spec("render.ao_samples", T::Int).def("2").ge(0).le(64),
      Spec("render.bulk", T::Enum)
          .def("auto")
          .choices({"auto", "volume", "surface", "particles", "none"}),
      Spec("render.volume_extinction", T::Number).def("250").unit("1/m").gt(0),
      Spec("render.iso_value", T::Number).def("0.5").gt(0),
      Spec("render.particle_radius", T::Number)
          .optional("half the particle spacing of the first source")
          .unit("m")
          .gt(0),
      Spec("render.ground", T::Bool).def("true"),
      Spec("render.key_light", T::Vec3)
          .optional("above and beside the camera")
          .unit_vector()
          .rule("points towards the light"),
      Spec("render.shell_front", T::Vec3).def("[0.8, 0.3, 0.2]").rule(kColorRule),
      Spec("render.shell_back", T::Vec3).def("[0.2, 0.42, 0.8]").rule(kColorRule),
      Spec("render.collider_color", T::Vec3).def("[0.45, 0.45, 0.48]").rule(kColorRule),
      Spec("render.ground_color", T::Vec3).def("[0.5, 0.5, 0.48]").rule(kColorRule),
      Spec("render.pattern", T::String)
          .def("preview.####.png")
          .rule(std::string("exactly one run of `#`; ends in .png; ") + kOutputFile),
      Spec("render.contact_sheet", T::Bool).def("true"),
      Spec("render.movie", T::Bool).def("true"),
      // shapes (the value of sources[].shape and colliders[].shape)
      Spec("shape.type", T::Enum).required().choices(kShapeTypes),
      Spec("shape.min", T::Vec3).required().unit("m").only_for({"box"}),
      Spec("shape.max", T::Vec3).required().unit("m").only_for({"box"}).rule("> min on every axis"),
      Spec("shape.center", T::Vec3).required().unit("m").only_for({"sphere", "cylinder"}),
      Spec("shape.radius", T::Number).required().unit("m").gt(0).only_for({"sphere", "cylinder"}),
      Spec("shape.axis", T::Vec3).required().unit_vector().only_for({"cylinder"}),
      Spec("shape.height", T::Number).required().unit("m").gt(0).only_for({"cylinder"}),
      Spec("shape.point", T::Vec3).required().unit("m").only_for({"plane"}),
      Spec("shape.normal", T::Vec3).required().unit_vector().only_for({"plane"}),
      Spec("shape.path", T::String)
          .required()
          .nonempty()
          .only_for({"mesh"})
          .rule("readable file; relative to the scene file"),
      Spec("shape.scale", T::Number).def("1").ge(1e-6).le(1e6).only_for({"mesh"}),
      Spec("shape.translate", T::Vec3).def("[0, 0, 0]").unit("m").only_for({"mesh"}),
  });
  return schema;
}

const std::unordered_map<std::string, const KeySpec*>& schema_index() {
  static const std::unordered_map<std::string, const KeySpec*> index = [] {
    std::unordered_map<std::string, const KeySpec*> m;
    for (const KeySpec& s : scene_schema()) m.emplace(s.key, &s);
    return m;
  }();
  return index;
}

const KeySpec* find_spec(const std::string& key) {
  auto it = schema_index().find(key);
  return it == schema_index().end() ? nullptr : it->second;
}

std::string join_key(const std::string& prefix, const std::string& name) {
  return prefix.empty() ? name : prefix + "." + name;
}

/// The schema prefix under which a key's children (or list items' keys) live.
std::string child_prefix(const KeySpec& s) {
  if (s.type == KeyType::Shape) return "shape";
  if (s.type == KeyType::List) return s.key + "[]";
  return s.key;
}

/// Names of the keys directly under `prefix`, in schema order; with `variant`, only those
/// allowed for that block type.
std::string known_keys(const std::string& prefix, const std::string* variant) {
  std::string out;
  const std::string head = prefix.empty() ? "" : prefix + ".";
  for (const KeySpec& s : scene_schema()) {
    if (s.key.compare(0, head.size(), head) != 0) continue;
    const std::string rest = s.key.substr(head.size());
    if (rest.find_first_of(".[") != std::string::npos) continue;
    if (variant && !s.only_for.empty() &&
        std::find(s.only_for.begin(), s.only_for.end(), *variant) == s.only_for.end()) {
      continue;
    }
    out += (out.empty() ? "" : ", ") + rest;
  }
  return out.empty() ? "none" : out;
}

std::string join(const std::vector<std::string>& v, const char* sep = ", ") {
  std::string out;
  for (const std::string& s : v) out += (out.empty() ? "" : sep) + s;
  return out;
}

/// "1e+20" -> "1e20", "1e-06" -> "1e-6": the exponent without sign or leading zeros.
std::string tidy_exponent(std::string s) {
  const std::size_t e = s.find('e');
  if (e != std::string::npos) {
    std::size_t d = e + 1;
    if (s[d] == '+') s.erase(d, 1);
    if (s[d] == '-') ++d;
    while (d + 1 < s.size() && s[d] == '0') s.erase(d, 1);
  }
  return s;
}

/// Shortest text that reads back as the same double ("0.5", "90", "4294967295", "1e-6").
std::string fmt_num(double x) {
  char buf[64];
  if (x == std::floor(x) && std::fabs(x) < 1e15) {
    std::snprintf(buf, sizeof buf, "%.0f", x);
    return buf;
  }
  for (int prec = 1; prec <= 17; ++prec) {
    std::snprintf(buf, sizeof buf, "%.*g", prec, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  std::string s = buf;  // "1e-06" -> "1e-6", "1e+20" -> "1e20"
  return tidy_exponent(s);
}

/// Three significant digits ("0.0417", "1.67e14").
std::string fmt3(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  std::string s = buf;  // "1.67e+14" -> "1.67e14", "1e-07" -> "1e-7"
  return tidy_exponent(s);
}

/// fmt_num, but a whole number from 1e6 on as "1e12" when that is shorter (tables).
std::string fmt_bound(double x) {
  const std::string whole = fmt_num(x);
  if (!(std::fabs(x) >= 1e6) || x != std::floor(x)) return whole;
  char buf[64];
  for (int prec = 1; prec <= 17; ++prec) {
    std::snprintf(buf, sizeof buf, "%.*e", prec - 1, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  std::string e = buf;  // "1e+12" -> "1e12", "2.5e+06" -> "2.5e6"
  const std::size_t at = e.find('e');
  std::string mant = e.substr(0, at), exp = e.substr(at + 1);
  if (exp[0] == '+') exp.erase(0, 1);
  while (exp.size() > 1 && exp[0] == '0') exp.erase(0, 1);
  const std::string shortest = mant + "e" + exp;
  return shortest.size() < whole.size() ? shortest : whole;
}

/// "(0, 1]", "> 0", ">= 0", "< 90", "= 1", or "" when unbounded.
std::string bounds_text(const KeySpec& s) {
  const bool lo = std::isfinite(s.min), hi = std::isfinite(s.max);
  if (lo && hi && s.min == s.max && !s.min_open && !s.max_open) return "= " + fmt_bound(s.min);
  if (lo && hi) {
    return std::string(s.min_open ? "(" : "[") + fmt_bound(s.min) + ", " + fmt_bound(s.max) +
           (s.max_open ? ")" : "]");
  }
  if (lo) return std::string(s.min_open ? "> " : ">= ") + fmt_bound(s.min);
  if (hi) return std::string(s.max_open ? "< " : "<= ") + fmt_bound(s.max);
  return "";
}

bool in_bounds(const KeySpec& s, double x) {
  if (s.min_open ? !(x > s.min) : !(x >= s.min)) return false;
  if (s.max_open ? !(x < s.max) : !(x <= s.max)) return false;
  return true;
}

/// "must be > 0", "must be in (0, 1]", "must be 1".
std::string bounds_requirement(const KeySpec& s) {
  std::string b = bounds_text(s);
  if (b.compare(0, 2, "= ") == 0) return "must be " + b.substr(2);
  if (b[0] == '(' || b[0] == '[') return "must be in " + b;
  return "must be " + b;
}

// ------------------------------------------------------------------------------------------
// Document tree: YAML nodes with where they came from
// ------------------------------------------------------------------------------------------

/// Where a value came from: a file and 1-based line, or "--set k=v" with line 0.
struct Origin {
  std::string where;
  int line = 0;
};

struct DocEntry;

struct DocNode {
  enum class Kind { Null, Scalar, List, Map };
  Kind kind = Kind::Null;
  std::string text;               ///< Scalar: the text as written
  bool plain = false;             ///< Scalar: unquoted and untagged (may be a number or boolean)
  std::vector<DocNode> items;     ///< List
  std::vector<DocEntry> entries;  ///< Map, in file order
  Origin origin;
};

struct DocEntry {
  std::string key;
  Origin key_origin;
  DocNode value;
};

const DocNode* find_entry(const DocNode& map, const std::string& key) {
  for (const DocEntry& e : map.entries)
    if (e.key == key) return &e.value;
  return nullptr;
}

[[noreturn]] void fail(const Origin& o, const std::string& key, const std::string& msg) {
  throw UserError(o.where, o.line, key, msg);
}

std::string describe(const DocNode& n) {
  switch (n.kind) {
    case DocNode::Kind::Null:
      return "nothing (null)";
    case DocNode::Kind::Scalar:
      return n.plain ? "'" + n.text + "'" : "the string \"" + n.text + "\"";
    case DocNode::Kind::List:
      return "a list of " + std::to_string(n.items.size()) + " item" +
             (n.items.size() == 1 ? "" : "s");
    case DocNode::Kind::Map:
      return "a mapping";
  }
  return "?";
}

/// Converts a yaml-cpp node. `from_file`: lines come from marks; otherwise line 0.
/// `fallback_line` is used for nodes without a useful mark (null values).
DocNode convert(const YAML::Node& n, const std::string& where, bool from_file, int fallback_line,
                const std::string& path) {
  DocNode d;
  const int mark_line = n.Mark().line;
  d.origin.where = where;
  d.origin.line = !from_file ? 0 : (mark_line >= 0 && !n.IsNull()) ? mark_line + 1 : fallback_line;
  switch (n.Type()) {
    case YAML::NodeType::Undefined:
    case YAML::NodeType::Null:
      d.kind = DocNode::Kind::Null;
      break;
    case YAML::NodeType::Scalar:
      d.kind = DocNode::Kind::Scalar;
      d.text = n.Scalar();
      d.plain = n.Tag() == "?";
      break;
    case YAML::NodeType::Sequence: {
      d.kind = DocNode::Kind::List;
      std::size_t i = 0;
      for (const YAML::Node& item : n) {
        d.items.push_back(
            convert(item, where, from_file, d.origin.line, path + "[" + std::to_string(i) + "]"));
        ++i;
      }
      break;
    }
    case YAML::NodeType::Map:
      d.kind = DocNode::Kind::Map;
      for (auto it = n.begin(); it != n.end(); ++it) {
        Origin ko{where, 0};
        if (from_file) {
          const int kl = it->first.Mark().line;
          ko.line = kl >= 0 ? kl + 1 : d.origin.line;
        }
        if (!it->first.IsScalar()) {
          fail(ko, path,
               "mapping keys must be plain words, got a " +
                   std::string(it->first.IsNull() ? "null" : "list or mapping") + " as a key" +
                   (path.empty() ? " at the top level" : ""));
        }
        const std::string key = it->first.Scalar();
        const std::string key_path = join_key(path, key);
        for (const DocEntry& e : d.entries) {
          if (e.key == key) {
            fail(ko, key_path,
                 "duplicate key '" + key + "'" +
                     (e.key_origin.line > 0
                          ? " (first at line " + std::to_string(e.key_origin.line) + ")"
                          : ""));
          }
        }
        d.entries.push_back(
            DocEntry{key, ko, convert(it->second, where, from_file, ko.line, key_path)});
      }
      break;
  }
  return d;
}

/// Parses YAML text into one document; syntax errors are UserErrors at the file and line.
YAML::Node load_yaml(const std::string& text, const std::string& where, const std::string& key,
                     bool from_file) {
  std::vector<YAML::Node> docs;
  try {
    docs = YAML::LoadAll(text);
  } catch (const YAML::Exception& e) {
    const int line = from_file && e.mark.line >= 0 ? e.mark.line + 1 : 0;
    if (!from_file || line == 0) throw UserError(where, line, key, "YAML syntax error: " + e.msg);
    // The text does not parse, so the key comes from indentation (io/yaml_key_near.h).
    const std::string near = yaml_key_near_line(text, line);
    throw UserError(where, line, "",
                    "YAML syntax error" +
                        (near.empty() ? std::string(" (before the first key)")
                                      : " in or after key " + near) +
                        ": " + e.msg);
  }
  if (docs.size() > 1) {
    throw UserError(where, 0, key,
                    "holds " + std::to_string(docs.size()) +
                        " YAML documents ('---' separators); a scene is one document");
  }
  return docs.empty() ? YAML::Node() : docs.front();
}

// ------------------------------------------------------------------------------------------
// Scalar conversions
// ------------------------------------------------------------------------------------------

bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

/// Decimal integer: [+-]?[0-9]+
bool int_syntax(const std::string& s) {
  std::size_t i = (!s.empty() && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
  if (i == s.size()) return false;
  for (; i < s.size(); ++i)
    if (!is_digit(s[i])) return false;
  return true;
}

/// Decimal real: [+-]? (digits [. digits?] | . digits) ([eE] [+-]? digits)?
bool real_syntax(const std::string& s) {
  std::size_t i = (!s.empty() && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
  std::size_t digits = 0;
  while (i < s.size() && is_digit(s[i])) ++i, ++digits;
  if (i < s.size() && s[i] == '.') {
    ++i;
    while (i < s.size() && is_digit(s[i])) ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    std::size_t exp_digits = 0;
    while (i < s.size() && is_digit(s[i])) ++i, ++exp_digits;
    if (exp_digits == 0) return false;
  }
  return i == s.size();
}

bool non_finite_word(std::string s) {
  if (!s.empty() && (s[0] == '+' || s[0] == '-')) s.erase(0, 1);
  if (!s.empty() && s[0] == '.') s.erase(0, 1);
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s == "inf" || s == "nan" || s == "infinity";
}

const char* skip_plus(const std::string& s) {
  return s.c_str() + (s[0] == '+' ? 1 : 0);
}

double to_number(const DocNode& n, const std::string& key) {
  if (n.kind != DocNode::Kind::Scalar || !n.plain) {
    fail(n.origin, key,
         "expected a number, got " + describe(n) +
             (n.kind == DocNode::Kind::Scalar ? " (write numbers without quotes)" : ""));
  }
  if (non_finite_word(n.text)) fail(n.origin, key, "must be a finite number, got " + n.text);
  if (!real_syntax(n.text)) fail(n.origin, key, "expected a number, got '" + n.text + "'");
  double x = 0;
  const char* first = skip_plus(n.text);
  const char* last = n.text.c_str() + n.text.size();
  auto [ptr, ec] = std::from_chars(first, last, x);
  if (ec == std::errc::result_out_of_range) {
    fail(n.origin, key, "number " + n.text + " is out of the range of a double");
  }
  SHELLMPM_CHECK(ec == std::errc() && ptr == last, "from_chars on '" << n.text << "'");
  if (!std::isfinite(x)) fail(n.origin, key, "must be a finite number, got " + n.text);
  return x;
}

long long to_integer(const DocNode& n, const std::string& key) {
  if (n.kind != DocNode::Kind::Scalar || !n.plain) {
    fail(n.origin, key,
         "expected an integer, got " + describe(n) +
             (n.kind == DocNode::Kind::Scalar ? " (write numbers without quotes)" : ""));
  }
  if (!int_syntax(n.text)) {
    fail(n.origin, key,
         "expected an integer, got '" + n.text + "'" +
             (real_syntax(n.text) ? " (no decimal point or exponent)" : ""));
  }
  long long v = 0;
  const char* first = skip_plus(n.text);
  const char* last = n.text.c_str() + n.text.size();
  auto [ptr, ec] = std::from_chars(first, last, v);
  if (ec == std::errc::result_out_of_range) {
    fail(n.origin, key, "integer " + n.text + " is too large");
  }
  SHELLMPM_CHECK(ec == std::errc() && ptr == last, "from_chars on '" << n.text << "'");
  return v;
}

std::string to_string_value(const DocNode& n, const std::string& key) {
  if (n.kind != DocNode::Kind::Scalar) fail(n.origin, key, "expected a string, got " + describe(n));
  return n.text;
}

// ------------------------------------------------------------------------------------------
// MapReader: one mapping read against the schema keys under one prefix
// ------------------------------------------------------------------------------------------

class MapReader {
 public:
  /// @param prefix schema prefix of the keys ("shot", "materials[]", "shape"; "" = top level)
  /// @param path   instance path for messages ("materials[2]"; "" = top level)
  /// @param defer_key_check the caller reads `type` first, then calls check_keys(&type)
  MapReader(const DocNode& node, std::string prefix, std::string path, bool defer_key_check)
      : node_(node), prefix_(std::move(prefix)), path_(std::move(path)) {
    if (node_.kind != DocNode::Kind::Map) {
      fail(node_.origin, path_,
           "expected a mapping (key: value lines or {...}), got " + describe(node_));
    }
    consumed_.assign(node_.entries.size(), false);
    if (!defer_key_check) check_keys(nullptr);
  }

  /// Rejects keys the schema does not know here, and keys not allowed for `variant` (the
  /// block's type) when given.
  void check_keys(const std::string* variant) const {
    for (const DocEntry& e : node_.entries) {
      const KeySpec* s = find_spec(join_key(prefix_, e.key));
      const std::string where_text = path_.empty() ? "the top level" : path_;
      if (!s) {
        fail(e.key_origin, path_of(e.key),
             "unknown key '" + e.key + "' in " + where_text + " (known" +
                 (variant ? " for type " + *variant : std::string()) + ": " +
                 known_keys(prefix_, variant) + ")");
      }
      if (variant && !s->only_for.empty() &&
          std::find(s->only_for.begin(), s->only_for.end(), *variant) == s->only_for.end()) {
        fail(e.key_origin, path_of(e.key),
             "'" + e.key + "' is not allowed for type " + *variant + " (only for " +
                 join(s->only_for) + "; keys for " + *variant + ": " +
                 known_keys(prefix_, variant) + ")");
      }
    }
  }

  bool has(const std::string& key) const { return index_of(key) >= 0; }
  std::string path_of(const std::string& key) const { return join_key(path_, key); }
  const Origin& origin() const { return node_.origin; }
  /// Origin of the key's value, or of this mapping when the key is absent.
  const Origin& origin_of(const std::string& key) const {
    const int i = index_of(key);
    return i >= 0 ? node_.entries[i].value.origin : node_.origin;
  }
  /// Origin of the key itself (for "not both" errors), or of this mapping.
  const Origin& key_origin_of(const std::string& key) const {
    const int i = index_of(key);
    return i >= 0 ? node_.entries[i].key_origin : node_.origin;
  }

  long long integer(const std::string& key) {
    const KeySpec& s = spec(key, KeyType::Int);
    const DocNode& v = value(key, s);
    const long long x = to_integer(v, path_of(key));
    if (!in_bounds(s, static_cast<double>(x))) {
      fail(v.origin, path_of(key), bounds_requirement(s) + ", got " + v.text);
    }
    return x;
  }

  int int32(const std::string& key) {
    const long long x = integer(key);
    if (x > INT_MAX || x < INT_MIN) {
      fail(origin_of(key), path_of(key), "integer " + std::to_string(x) + " is too large");
    }
    return static_cast<int>(x);
  }

  double number(const std::string& key) {
    const KeySpec& s = spec(key, KeyType::Number);
    const DocNode& v = value(key, s);
    const double x = to_number(v, path_of(key));
    if (!in_bounds(s, x)) fail(v.origin, path_of(key), bounds_requirement(s) + ", got " + v.text);
    return x;
  }

  bool boolean(const std::string& key) {
    const KeySpec& s = spec(key, KeyType::Bool);
    const DocNode& v = value(key, s);
    if (v.kind == DocNode::Kind::Scalar && v.plain && v.text == "true") return true;
    if (v.kind == DocNode::Kind::Scalar && v.plain && v.text == "false") return false;
    fail(v.origin, path_of(key), "expected true or false, got " + describe(v));
  }

  std::string string(const std::string& key) {
    const KeySpec& s = spec(key, KeyType::String);
    const DocNode& v = value(key, s);
    std::string x = to_string_value(v, path_of(key));
    if (s.nonempty && x.empty()) fail(v.origin, path_of(key), "must not be empty");
    return x;
  }

  std::string choice(const std::string& key) {
    const KeySpec& s = spec(key, KeyType::Enum);
    const DocNode& v = value(key, s);
    if (v.kind != DocNode::Kind::Scalar) {
      fail(v.origin, path_of(key), "expected one of " + join(s.choices) + ", got " + describe(v));
    }
    if (std::find(s.choices.begin(), s.choices.end(), v.text) == s.choices.end()) {
      fail(v.origin, path_of(key), "expected one of " + join(s.choices) + ", got '" + v.text + "'");
    }
    return v.text;
  }

  Vec3d vec3(const std::string& key) {
    const KeySpec& s = spec(key, KeyType::Vec3);
    const DocNode& v = value(key, s);
    if (v.kind != DocNode::Kind::List || v.items.size() != 3) {
      fail(v.origin, path_of(key), "expected a list of 3 numbers [x, y, z], got " + describe(v));
    }
    Vec3d x;
    for (int i = 0; i < 3; ++i) {
      const std::string item_key = path_of(key) + "[" + std::to_string(i) + "]";
      x[i] = to_number(v.items[i], item_key);
      if (!in_bounds(s, x[i])) {
        fail(v.items[i].origin, item_key, bounds_requirement(s) + ", got " + v.items[i].text);
      }
    }
    if (s.unit_vector) {
      const double len = x.norm();
      if (!(len > 0.0) || !std::isfinite(len)) {
        fail(v.origin, path_of(key), "must be a nonzero vector, got [0, 0, 0]");
      }
      x /= len;
    }
    return x;
  }

  std::pair<int, int> frames(const std::string& key) {
    const KeySpec& s = spec(key, KeyType::FrameRange);
    const DocNode& v = value(key, s);
    if (v.kind != DocNode::Kind::List || v.items.size() != 2) {
      fail(v.origin, path_of(key), "expected [first, last] frames, got " + describe(v));
    }
    int f[2];
    for (int i = 0; i < 2; ++i) {
      const std::string item_key = path_of(key) + "[" + std::to_string(i) + "]";
      const long long x = to_integer(v.items[i], item_key);
      if (!in_bounds(s, static_cast<double>(x)) || x > INT_MAX) {
        fail(v.items[i].origin, item_key,
             (x > INT_MAX ? std::string("is too large") : bounds_requirement(s)) + ", got " +
                 v.items[i].text);
      }
      f[i] = static_cast<int>(x);
    }
    if (f[1] < f[0]) {
      fail(v.origin, path_of(key),
           "last frame " + std::to_string(f[1]) + " is before first frame " + std::to_string(f[0]));
    }
    return {f[0], f[1]};
  }

  /// A list of exactly 2 numbers, each within the bounds.
  std::array<double, 2> vec2(const std::string& key) {
    const KeySpec& s = spec(key, KeyType::Vec2);
    const DocNode& v = value(key, s);
    if (v.kind != DocNode::Kind::List || v.items.size() != 2) {
      fail(v.origin, path_of(key), "expected a list of 2 numbers, got " + describe(v));
    }
    std::array<double, 2> x{};
    for (int i = 0; i < 2; ++i) {
      const std::string item_key = path_of(key) + "[" + std::to_string(i) + "]";
      x[i] = to_number(v.items[i], item_key);
      if (!in_bounds(s, x[i])) {
        fail(v.items[i].origin, item_key, bounds_requirement(s) + ", got " + v.items[i].text);
      }
    }
    return x;
  }

  /// A list of exactly 2 integers, each within the bounds.
  std::array<int, 2> int2(const std::string& key) {
    const KeySpec& s = spec(key, KeyType::Int2);
    const DocNode& v = value(key, s);
    if (v.kind != DocNode::Kind::List || v.items.size() != 2) {
      fail(v.origin, path_of(key), "expected a list of 2 integers, got " + describe(v));
    }
    std::array<int, 2> x{};
    for (int i = 0; i < 2; ++i) {
      x[i] = bounded_int(s, v.items[i], path_of(key) + "[" + std::to_string(i) + "]");
    }
    return x;
  }

  /// A non-empty list of integers, each within the bounds.
  std::vector<int> int_list(const std::string& key) {
    const KeySpec& s = spec(key, KeyType::IntList);
    const DocNode& v = value(key, s);
    if (v.kind != DocNode::Kind::List) {
      fail(v.origin, path_of(key), "expected a list of integers, got " + describe(v));
    }
    if (v.items.empty()) fail(v.origin, path_of(key), "must not be empty");
    std::vector<int> x;
    for (std::size_t i = 0; i < v.items.size(); ++i) {
      x.push_back(bounded_int(s, v.items[i], path_of(key) + "[" + std::to_string(i) + "]"));
    }
    return x;
  }

  /// A list of exactly 3 booleans.
  std::array<bool, 3> bool3(const std::string& key) {
    const KeySpec& s = spec(key, KeyType::Bool3);
    const DocNode& v = value(key, s);
    if (v.kind != DocNode::Kind::List || v.items.size() != 3) {
      fail(v.origin, path_of(key), "expected a list of 3 booleans [x, y, z], got " + describe(v));
    }
    std::array<bool, 3> x{};
    for (int i = 0; i < 3; ++i) {
      const DocNode& item = v.items[i];
      const bool ok = item.kind == DocNode::Kind::Scalar && item.plain &&
                      (item.text == "true" || item.text == "false");
      if (!ok) {
        fail(item.origin, path_of(key) + "[" + std::to_string(i) + "]",
             "expected true or false, got " + describe(item));
      }
      x[i] = item.text == "true";
    }
    return x;
  }

  /// The value node of a present key (not marked read), or nullptr.
  const DocNode* present(const std::string& key) const {
    const int i = index_of(key);
    return i >= 0 ? &node_.entries[i].value : nullptr;
  }

  /// A Map, List or Shape value: the given one, the default, or nullptr when an Optional key
  /// is absent. Checks the node kind.
  const DocNode* block(const std::string& key) {
    const KeySpec& s = spec(key, KeyType::Map, KeyType::List, KeyType::Shape);
    if (s.presence == Presence::Optional && !has(key)) return nullptr;
    const DocNode& v = value(key, s);
    const bool want_list = s.type == KeyType::List;
    const DocNode::Kind want = want_list ? DocNode::Kind::List : DocNode::Kind::Map;
    if (v.kind != want) {
      fail(v.origin, path_of(key),
           std::string(want_list ? "expected a list (write [] for none), got "
                                 : "expected a mapping (key: value lines or {...}), got ") +
               describe(v));
    }
    return &v;
  }

  /// Internal check: every key present was read by the code (the schema has no dead keys).
  void finish() const {
    for (std::size_t i = 0; i < node_.entries.size(); ++i) {
      SHELLMPM_CHECK(consumed_[i], "scene key " << path_of(node_.entries[i].key)
                                                << " is in the schema but was never read");
    }
  }

 private:
  int index_of(const std::string& key) const {
    for (std::size_t i = 0; i < node_.entries.size(); ++i)
      if (node_.entries[i].key == key) return static_cast<int>(i);
    return -1;
  }

  static int bounded_int(const KeySpec& s, const DocNode& item, const std::string& item_key) {
    const long long x = to_integer(item, item_key);
    if (!in_bounds(s, static_cast<double>(x))) {
      fail(item.origin, item_key, bounds_requirement(s) + ", got " + item.text);
    }
    if (x > INT_MAX || x < INT_MIN)
      fail(item.origin, item_key, "integer " + item.text + " is too large");
    return static_cast<int>(x);
  }

  const KeySpec& spec(const std::string& key, KeyType t1, KeyType t2 = KeyType::Int,
                      KeyType t3 = KeyType::Int) const {
    const KeySpec* s = find_spec(join_key(prefix_, key));
    SHELLMPM_CHECK(s != nullptr, "no schema entry for " << join_key(prefix_, key));
    SHELLMPM_CHECK(s->type == t1 || s->type == t2 || s->type == t3,
                   "schema type of " << s->key << " does not match the reader");
    return *s;
  }

  /// The present value (marked read), or the schema default, or a missing-key error.
  const DocNode& value(const std::string& key, const KeySpec& s) {
    const int i = index_of(key);
    if (i >= 0) {
      consumed_[i] = true;
      return node_.entries[i].value;
    }
    if (s.presence == Presence::Required) {
      std::string hint;
      if (s.type == KeyType::Enum) hint = " (one of " + join(s.choices) + ")";
      fail(node_.origin, path_of(key), "required key '" + key + "' is missing" + hint);
    }
    SHELLMPM_CHECK(s.presence == Presence::Default,
                   "optional key " << s.key << " read without a has() check");
    // A default is validated exactly like user input; it is reported at this mapping.
    defaults_.push_back(convert(load_yaml(s.default_value, "default of " + s.key, s.key, false),
                                node_.origin.where, false, 0, s.key));
    set_origin(defaults_.back(), node_.origin);
    return defaults_.back();
  }

  static void set_origin(DocNode& n, const Origin& o) {
    n.origin = o;
    for (DocNode& c : n.items) set_origin(c, o);
    for (DocEntry& e : n.entries) {
      e.key_origin = o;
      set_origin(e.value, o);
    }
  }

  const DocNode& node_;
  std::string prefix_;
  std::string path_;
  std::vector<bool> consumed_;
  std::deque<DocNode> defaults_;  // stable addresses for returned defaults
};

// ------------------------------------------------------------------------------------------
// Overrides: "a.b[0].c=value" set into the document before validation
// ------------------------------------------------------------------------------------------

struct PathSeg {
  std::string name;  ///< key name, or empty for an index
  std::size_t index = 0;
  bool is_index = false;
};

std::vector<PathSeg> split_override_path(const std::string& key, const std::string& where) {
  std::vector<PathSeg> segs;
  std::size_t i = 0;
  auto bad = [&](const std::string& why) {
    throw UserError(where, 0, "", "bad key path '" + key + "': " + why);
  };
  auto parse_index = [&](const std::string& digits) {
    std::size_t v = 0;
    auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
    if (ec != std::errc() || ptr != digits.data() + digits.size()) bad("bad index " + digits);
    return v;
  };
  while (true) {
    std::size_t j = i;
    while (j < key.size() && key[j] != '.' && key[j] != '[') ++j;
    const std::string name = key.substr(i, j - i);
    if (name.empty()) bad("empty key name");
    const bool digits = std::all_of(name.begin(), name.end(), is_digit);
    segs.push_back(digits ? PathSeg{"", parse_index(name), true} : PathSeg{name, 0, false});
    while (j < key.size() && key[j] == '[') {
      const std::size_t close = key.find(']', j);
      if (close == std::string::npos) bad("missing ']'");
      const std::string idx = key.substr(j + 1, close - j - 1);
      if (idx.empty() || !std::all_of(idx.begin(), idx.end(), is_digit)) {
        bad("list index must be a number, got [" + idx + "]");
      }
      segs.push_back(PathSeg{"", parse_index(idx), true});
      j = close + 1;
    }
    if (j == key.size()) break;
    if (key[j] != '.') bad("expected '.' or '[' after ']'");
    i = j + 1;
  }
  return segs;
}

/// What in an override's text YAML reads as syntax, for the quoting hint: "'{' starts a
/// YAML flow mapping"; empty when nothing stands out.
std::string yaml_special_in(const std::string& text) {
  const std::size_t first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  const char c = text[first];
  switch (c) {
    case '{':
      return "'{' starts a YAML flow mapping";
    case '[':
      return "'[' starts a YAML flow list";
    case '#':
      return "'#' at the start starts a YAML comment";
    case '*':
      return "'*' starts a YAML alias";
    case '&':
      return "'&' starts a YAML anchor";
    case '!':
      return "'!' starts a YAML tag";
    case '|':
    case '>':
      return std::string("'") + c + "' starts a YAML block scalar";
    case '%':
      return "'%' starts a YAML directive";
    case '@':
    case '`':
      return std::string("'") + c + "' is reserved in YAML";
    case '"':
    case '\'':
      return std::string("the quote ") + c + " at the start is not closed at the end";
    default:
      break;
  }
  if (text.compare(first, 3, "---") == 0) return "'---' starts a new YAML document";
  if (text.compare(first, 2, "- ") == 0) return "'- ' starts a YAML list item";
  for (std::size_t i = first + 1; i < text.size(); ++i) {
    if (text[i] == '#' && (text[i - 1] == ' ' || text[i - 1] == '\t'))
      return "' #' starts a YAML comment";
    if (text[i] == ':' && (i + 1 == text.size() || text[i + 1] == ' '))
      return "': ' makes it a YAML mapping";
  }
  return "";
}

/// `--set 'KEY="VALUE"'`: the override with VALUE as a YAML double-quoted string, the
/// whole argument in shell single quotes.
std::string quoted_override(const std::string& key, const std::string& value) {
  std::string yaml = "\"";
  for (char c : value) {
    if (c == '"' || c == '\\') yaml += '\\';
    yaml += c;
  }
  yaml += "\"";
  std::string arg = key + "=" + yaml, shell = "'";
  for (char c : arg) shell += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return "--set " + shell + "'";
}

/// Parses an override's value. A value YAML does not read as one plain value (a syntax
/// error, several documents, a comment where a value was meant, a mapping or list for a
/// string key) is an error that names the character and shows the quoted form.
YAML::Node load_override_value(const std::string& text, const std::string& where,
                               const std::string& key, const KeySpec* spec) {
  std::string problem;
  YAML::Node value;
  std::vector<YAML::Node> docs;
  try {
    docs = YAML::LoadAll(text);
  } catch (const YAML::Exception& e) {
    problem = "YAML syntax error: " + e.msg;
  }
  if (problem.empty() && docs.size() > 1)
    problem = "YAML reads it as " + std::to_string(docs.size()) + " documents";
  if (problem.empty() && !docs.empty()) value = docs.front();
  const bool blank = text.find_first_not_of(" \t") == std::string::npos;
  if (problem.empty() && (docs.empty() || value.IsNull()) && !blank && text != "null" &&
      text != "~" && text != "Null" && text != "NULL")
    problem = "YAML reads it as nothing (null)";
  const bool wants_word = spec && (spec->type == KeyType::String || spec->type == KeyType::Enum);
  // A plain word cut short by " #" (the rest read as a comment) is not what was meant.
  if (problem.empty() && value.IsScalar() && value.Tag() == "?" &&
      (text.find(" #") != std::string::npos || text.find("\t#") != std::string::npos))
    problem = "YAML reads it as '" + value.Scalar() + "': the rest is a comment";
  if (problem.empty() && wants_word && (value.IsMap() || value.IsSequence()))
    problem = std::string("YAML reads it as a ") + (value.IsMap() ? "mapping" : "list");
  if (problem.empty()) return value;
  const std::string special = yaml_special_in(text);
  throw UserError(where, 0, key,
                  "the value '" + text + "' is not one plain YAML value (" + problem + ")" +
                      (special.empty() ? "" : ": " + special) +
                      ". Quote it for YAML, and the whole argument for the shell: " +
                      quoted_override(key, text));
}

void apply_override(DocNode& root, const std::string& ov) {
  const std::string where = "--set " + ov;
  const std::size_t eq = ov.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw UserError(where, 0, "", "expected KEY=VALUE, e.g. shot.dx=0.01");
  }
  const std::string key = ov.substr(0, eq);
  const std::string text = ov.substr(eq + 1);
  const std::vector<PathSeg> segs = split_override_path(key, where);
  const Origin origin{where, 0};

  // State while walking: the node, what the schema says it is, and its schema prefix.
  enum class Expect { Map, List, Leaf };
  DocNode* cur = &root;
  Expect expect = Expect::Map;
  std::string prefix;  // Map: prefix of its keys; List: prefix of its items' keys
  std::string path;    // instance path so far
  const KeySpec* leaf = nullptr;  // the schema entry of the last key segment
  for (std::size_t si = 0; si < segs.size(); ++si) {
    const PathSeg& seg = segs[si];
    const bool last = si + 1 == segs.size();
    const std::string shown = path.empty() ? "the top level" : path;
    if (seg.is_index) {
      const std::string item_path = path + "[" + std::to_string(seg.index) + "]";
      if (expect != Expect::List) {
        throw UserError(where, 0, item_path, shown + " is not a list");
      }
      if (cur->kind != DocNode::Kind::List) {
        throw UserError(where, 0, item_path,
                        path + " is " + describe(*cur) + " in the scene, not a list");
      }
      if (seg.index >= cur->items.size()) {
        throw UserError(where, 0, item_path,
                        "index " + std::to_string(seg.index) + " is out of range: " + path +
                            " has " + std::to_string(cur->items.size()) + " entr" +
                            (cur->items.size() == 1 ? "y" : "ies"));
      }
      cur = &cur->items[seg.index];
      path = item_path;
      expect = Expect::Map;  // every list in the format is a list of mappings
      if (last) break;
      continue;
    }
    const std::string key_path = join_key(path, seg.name);
    if (expect == Expect::List) {
      throw UserError(where, 0, key_path,
                      path + " is a list; select an entry by index, e.g. " + path + "[0]." +
                          seg.name + " or " + path + ".0." + seg.name);
    }
    const KeySpec* s = expect == Expect::Map ? find_spec(join_key(prefix, seg.name)) : nullptr;
    if (!s) {
      throw UserError(where, 0, key_path,
                      "unknown key '" + seg.name + "' in " + shown + " (known: " +
                          (expect == Expect::Map ? known_keys(prefix, nullptr)
                                                 : "none; " + path + " has no sub-keys") +
                          ")");
    }
    if (cur->kind != DocNode::Kind::Map) {
      throw UserError(where, 0, key_path,
                      shown + " is " + describe(*cur) + " in the scene, not a mapping");
    }
    DocEntry* entry = nullptr;
    for (DocEntry& e : cur->entries)
      if (e.key == seg.name) entry = &e;
    if (!entry) {
      DocNode fresh;
      fresh.origin = origin;
      fresh.kind = s->type == KeyType::List ? DocNode::Kind::List : DocNode::Kind::Map;
      cur->entries.push_back(DocEntry{seg.name, origin, fresh});
      entry = &cur->entries.back();
    }
    cur = &entry->value;
    path = key_path;
    leaf = s;
    prefix = child_prefix(*s);
    expect = s->type == KeyType::List                                 ? Expect::List
             : (s->type == KeyType::Map || s->type == KeyType::Shape) ? Expect::Map
                                                                      : Expect::Leaf;
  }
  const bool item = !segs.empty() && segs.back().is_index;  // a whole list entry: a mapping
  *cur =
      convert(load_override_value(text, where, path, item ? nullptr : leaf), where, false, 0, path);
}

// ------------------------------------------------------------------------------------------
// Building the Scene
// ------------------------------------------------------------------------------------------

constexpr const char* kAxis[3] = {"x", "y", "z"};

void require_greater(const Vec3d& lo, const Vec3d& hi, const Origin& o, const std::string& key) {
  for (int a = 0; a < 3; ++a) {
    if (!(hi[a] > lo[a])) {
      fail(o, key,
           std::string("must be greater than min on every axis, but on ") + kAxis[a] +
               " max = " + fmt_num(hi[a]) + " <= min = " + fmt_num(lo[a]));
    }
  }
}

void require_one_hash_run(const std::string& pattern, const Origin& o, const std::string& key) {
  int runs = 0;
  for (std::size_t i = 0; i < pattern.size(); ++i)
    if (pattern[i] == '#' && (i == 0 || pattern[i - 1] != '#')) ++runs;
  if (runs != 1) {
    fail(o, key,
         "must contain exactly one run of '#' (replaced by the zero-padded frame number), got '" +
             pattern + "'");
  }
}

/// A file name inside output.directory: relative, naming a file (not a folder), with any
/// sub-folders before it; the `#` run of a pattern (`is_pattern`) in the file name itself,
/// since the folders are made once before the run (io/output_folders.h).
void require_output_file(const std::string& path, bool is_pattern, const Origin& o,
                         const std::string& key) {
  if (!path.empty() && path.front() == '/') {
    fail(o, key,
         "must be relative to output.directory (files are written inside it), got '" + path + "'");
  }
  const std::size_t slash = path.rfind('/');
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  if (name.empty() || name == "." || name == "..") {
    fail(o, key, "must end in a file name, got '" + path + "'");
  }
  if (is_pattern && slash != std::string::npos && path.find('#') < slash) {
    fail(
        o, key,
        "the '#' run (frame number) must be in the file name, not in a folder: got '" + path + "'");
  }
}

/// "file:line: key" (or "--set K=V: key"), the prefix of a UserError, for fields that io/
/// reports problems at after the scene is read.
std::string where_text(const Origin& o, const std::string& key) {
  return (o.line > 0 ? o.where + ":" + std::to_string(o.line) : o.where) + ": " + key;
}

/// A UserError at a where_text() string ("file:line: key", "--set K=V: key"), with `suffix`
/// appended to the key; at `fallback_file` / `fallback_key` when `where` is empty.
UserError error_at_where(const std::string& where, const std::string& fallback_file,
                         const std::string& fallback_key, const std::string& suffix,
                         const std::string& message) {
  if (where.empty()) return UserError(fallback_file, 0, fallback_key + suffix, message);
  // Keys never hold ": ", so the last one ends the location. A "--set" location has no line.
  const std::size_t sep = where.rfind(": ");
  std::string head = sep == std::string::npos ? where : where.substr(0, sep);
  const std::string key = sep == std::string::npos ? fallback_key : where.substr(sep + 2);
  int line = 0;
  const std::size_t colon = head.rfind(':');
  if (head.compare(0, 6, "--set ") != 0 && colon != std::string::npos && colon + 1 < head.size() &&
      head.size() - colon - 1 < 10 &&
      std::all_of(head.begin() + static_cast<std::ptrdiff_t>(colon) + 1, head.end(), is_digit)) {
    line = std::stoi(head.substr(colon + 1));
    head.erase(colon);
  }
  return UserError(head, line, key + suffix, message);
}

/// Reads a mesh file path, resolved relative to the scene file; the file must be readable.
/// Returns the resolved path and where it was given ("file:line: key").
std::pair<std::string, std::string> read_mesh_path(MapReader& r, const std::string& key,
                                                   const std::string& scene_path) {
  const std::string raw = r.string(key);
  fs::path p(raw);
  if (p.is_relative()) p = fs::path(scene_path).parent_path() / p;
  p = p.lexically_normal();
  const Origin& o = r.origin_of(key);
  std::error_code ec;
  const fs::file_status st = fs::status(p, ec);
  if (!fs::exists(st)) fail(o, r.path_of(key), "mesh file not found: " + p.string());
  if (!fs::is_regular_file(st)) fail(o, r.path_of(key), "not a regular file: " + p.string());
  if (!std::ifstream(p, std::ios::binary)) {
    fail(o, r.path_of(key), "cannot read mesh file " + p.string() + ": " + std::strerror(errno));
  }
  return {p.string(), where_text(o, r.path_of(key))};
}

/// Fails at `key` when a coordinate of `p` lies beyond the position range
/// (kPositionRangeCells cells of the origin); `what` names p ("the translation").
void require_in_position_range(const Vec3d& p, const ShotSettings& shot, const Origin& o,
                               const std::string& key, const std::string& what) {
  const double range = kPositionRangeCells * shot.dx;
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(p[a]) <= range) continue;
    fail(o, key,
         what + " reaches " + kAxis[a] + " = " + fmt_num(p[a]) +
             " m, more than 2^17 = 131072 cells of dx = " + fmt_num(shot.dx) + " m (" +
             fmt_num(range) +
             " m) from the origin, where a float position no longer resolves "
             "1/64 of a cell");
  }
}

/// Reads the keyframe list at `key` (items with the schema keys under `item_prefix`); frame N
/// is at time (N - 1) / fps. Times must strictly increase.
std::vector<Keyframe> read_keyframes(MapReader& r, const std::string& key,
                                     const std::string& item_prefix, const ShotSettings& shot) {
  const double fps = shot.fps;
  std::vector<Keyframe> out;
  const DocNode& keys = *r.block(key);
  for (std::size_t k = 0; k < keys.items.size(); ++k) {
    const std::string kp = r.path_of(key) + "[" + std::to_string(k) + "]";
    MapReader kr(keys.items[k], item_prefix, kp, false);
    Keyframe kf;
    const bool has_time = kr.has("time"), has_frame = kr.has("frame");
    if (has_time && has_frame) {
      fail(kr.key_origin_of("frame"), kp, "give either time or frame, not both");
    }
    if (!has_time && !has_frame) fail(kr.origin(), kp, "needs a time (seconds) or a frame");
    // Frame N is the state written as frame N, at t = (N - 1) / fps (frame 1 = start).
    kf.time = has_time ? kr.number("time") : (kr.int32("frame") - 1) / fps;
    const std::string tkey = has_time ? "time" : "frame";
    if (!out.empty() && !(kf.time > out.back().time)) {
      fail(kr.origin_of(tkey), kr.path_of(tkey),
           "keyframe times must strictly increase: " + fmt_num(kf.time) + " s is not after " +
               fmt_num(out.back().time) + " s (keyframe " + std::to_string(k - 1) + ")");
    }
    kf.translate = kr.vec3("translate");
    require_in_position_range(kf.translate, shot, kr.origin_of("translate"),
                              kr.path_of("translate"), "the translation");
    kf.rotate_deg = kr.vec3("rotate");
    kr.finish();
    out.push_back(kf);
  }
  return out;
}

/// A linear RGB colour: a vec3 with every component in [0, 1].
Vec3d read_color(MapReader& r, const std::string& key) {
  const Vec3d c = r.vec3(key);
  for (int a = 0; a < 3; ++a) {
    if (!(c[a] >= 0.0 && c[a] <= 1.0)) {
      fail(r.origin_of(key), r.path_of(key) + "[" + std::to_string(a) + "]",
           "a colour component must be in [0, 1] (linear RGB), got " + fmt_num(c[a]));
    }
  }
  return c;
}

void read_render(const DocNode& node, RenderSettings& rs) {
  MapReader r(node, "render", "render", false);
  rs.preview = r.boolean("preview");
  rs.renderer = r.choice("renderer");
  const std::array<int, 2> size = r.int2("size");
  rs.width = size[0];
  rs.height = size[1];
  const DocNode& cams = *r.block("cameras");
  for (std::size_t i = 0; i < cams.items.size(); ++i) {
    const std::string p = r.path_of("cameras") + "[" + std::to_string(i) + "]";
    MapReader c(cams.items[i], "render.cameras[]", p, false);
    RenderCamera cam;
    cam.name = c.string("name");
    if (cam.name == "auto") {
      fail(c.origin_of("name"), c.path_of("name"),
           "'auto' is the automatic camera's name; choose another name");
    }
    for (const RenderCamera& o : rs.cameras) {
      if (o.name == cam.name)
        fail(c.origin_of("name"), c.path_of("name"), "duplicate camera name '" + cam.name + "'");
    }
    cam.position = c.vec3("position");
    cam.target = c.vec3("target");
    const Vec3d view = cam.target - cam.position;
    if (!(view.norm() > 0.0)) {
      fail(c.origin_of("target"), c.path_of("target"), "must differ from position");
    }
    cam.up = c.vec3("up");
    if (view.normalized().cross(cam.up).norm() < 1e-6) {
      fail(c.origin_of("up"), c.path_of("up"),
           "must not be parallel to the view direction (target - position)");
    }
    cam.fov_deg = c.number("fov");
    c.finish();
    rs.cameras.push_back(cam);
  }
  if (r.has("camera")) {
    rs.camera = r.string("camera");
    bool known = rs.camera == "auto";
    std::vector<std::string> names{"auto"};
    for (const RenderCamera& c : rs.cameras) {
      known = known || c.name == rs.camera;
      names.push_back(c.name);
    }
    if (!known) {
      fail(r.origin_of("camera"), r.path_of("camera"),
           "unknown camera '" + rs.camera + "' (cameras: " + join(names) + ")");
    }
  }
  rs.samples = r.int32("samples");
  rs.ao_samples = r.int32("ao_samples");
  rs.bulk = r.choice("bulk");
  rs.volume_extinction = r.number("volume_extinction");
  rs.iso_value = r.number("iso_value");
  rs.particle_radius = r.has("particle_radius") ? r.number("particle_radius") : 0.0;
  rs.ground = r.boolean("ground");
  if (r.has("key_light")) rs.key_light = r.vec3("key_light");
  rs.shell_front = read_color(r, "shell_front");
  rs.shell_back = read_color(r, "shell_back");
  rs.collider_color = read_color(r, "collider_color");
  rs.ground_color = read_color(r, "ground_color");
  rs.pattern = r.string("pattern");
  require_one_hash_run(rs.pattern, r.origin_of("pattern"), r.path_of("pattern"));
  require_output_file(rs.pattern, true, r.origin_of("pattern"), r.path_of("pattern"));
  if (rs.pattern.size() < 4 || rs.pattern.compare(rs.pattern.size() - 4, 4, ".png") != 0) {
    fail(r.origin_of("pattern"), r.path_of("pattern"),
         "must end in .png, got '" + rs.pattern + "'");
  }
  rs.contact_sheet = r.boolean("contact_sheet");
  rs.movie = r.boolean("movie");
  r.finish();
}

void read_shot(const DocNode& node, ShotSettings& shot) {
  MapReader r(node, "shot", "shot", false);
  std::tie(shot.frame_start, shot.frame_end) = r.frames("frames");
  shot.fps = r.number("fps");
  shot.cfl = r.number("cfl");
  shot.dt_min = r.number("dt_min");
  shot.dt_max = r.number("dt_max");
  if (shot.dt_max < shot.dt_min) {
    const std::string at = r.has("dt_max") ? "dt_max" : "dt_min";
    fail(r.origin_of(at), r.path_of(at),
         "dt_max (" + fmt_num(shot.dt_max) + ") must be >= dt_min (" + fmt_num(shot.dt_min) + ")");
  }
  shot.gravity = r.vec3("gravity");
  {
    MapReader d(*r.block("domain"), "shot.domain", "shot.domain", false);
    shot.domain_min = d.vec3("min");
    shot.domain_max = d.vec3("max");
    require_greater(shot.domain_min, shot.domain_max, d.origin_of("max"), d.path_of("max"));
    d.finish();
  }
  shot.dx = r.number("dx");
  {
    // Every corner within the position range (float resolves 1/64 cell there).
    const double range = kPositionRangeCells * shot.dx;
    MapReader d(*r.block("domain"), "shot.domain", "shot.domain", false);
    for (const char* corner : {"min", "max"}) {
      const Vec3d c = std::string(corner) == "min" ? shot.domain_min : shot.domain_max;
      for (int a = 0; a < 3; ++a) {
        if (std::fabs(c[a]) <= range) continue;
        fail(d.origin_of(corner), d.path_of(corner) + "[" + std::to_string(a) + "]",
             std::string("coordinate ") + kAxis[a] + " = " + fmt_num(c[a]) +
                 " m is more than 2^17 = 131072 cells of dx = " + fmt_num(shot.dx) + " m (" +
                 fmt_num(range) +
                 " m) from the origin, where a float position can no longer "
                 "resolve 1/64 of a cell; move the shot towards the origin or use a larger dx");
      }
    }
  }
  // Steps a frame may take before dt_min stops the run: a bound on the work of a frame.
  {
    const double steps = 1.0 / (shot.fps * shot.dt_min);
    if (!(steps <= kMaxStepsPerFrame)) {
      // Name what the user wrote; with both, dt_min when it is below its default.
      const bool small_dt_min = r.has("dt_min") && shot.dt_min < 1e-6;
      const std::string at = r.has("fps") && !small_dt_min ? "fps"
                             : r.has("dt_min")             ? "dt_min"
                                                           : "fps";
      fail(r.origin_of(at), r.path_of(at),
           "a frame (1 / fps = " + fmt3(1.0 / shot.fps) + " s) may take up to " +
               fmt_bound(std::ceil(steps)) + " steps of dt_min = " + fmt_num(shot.dt_min) +
               " s (at most 1e7: such a run would seem to hang); raise shot.fps or shot.dt_min");
    }
  }
  constexpr double kMaxCells = 1 << 20;
  for (int a = 0; a < 3; ++a) {
    const double cells = (shot.domain_max[a] - shot.domain_min[a]) / shot.dx;
    if (cells > kMaxCells) {
      fail(r.origin_of("dx"), r.path_of("dx"),
           "the domain is " + fmt_num(std::ceil(cells)) + " cells along " + kAxis[a] +
               " (at most 2^20 = 1048576); use a larger dx or a smaller domain");
    }
  }
  shot.threads = r.int32("threads");
  shot.transfer = r.choice("transfer");
  shot.shared_shell_velocity = r.choice("shell_velocities") == "shared";
  shot.fold_fields = r.boolean("fold_fields");
  shot.shell_guard = r.boolean("shell_guard");
  shot.shell_guard_gap = r.number("shell_guard_gap");
  shot.units = r.string("units");
  shot.on_integrity_failure = r.choice("on_integrity_failure") == "stop"
                                  ? ShotSettings::OnIntegrityFailure::Stop
                                  : ShotSettings::OnIntegrityFailure::Warn;
  r.finish();
}

MaterialDesc read_material(const DocNode& node, const std::string& path) {
  MapReader r(node, "materials[]", path, true);
  MaterialDesc m;
  m.name = r.string("name");
  const std::string type = r.choice("type");
  r.check_keys(&type);
  m.kind = type == "elastic" ? MaterialKind::Elastic
           : type == "sand"  ? MaterialKind::Sand
                             : MaterialKind::Snow;
  if (m.kind == MaterialKind::Elastic) {
    m.model = r.choice("model") == "neo_hookean" ? ElasticModel::NeoHookean
                                                 : ElasticModel::FixedCorotated;
  }
  m.youngs_modulus = r.number("youngs_modulus");
  m.poisson_ratio = r.number("poisson_ratio");
  m.density = r.number("density");
  if (m.kind == MaterialKind::Sand) {
    m.friction_angle_deg = r.number("friction_angle");
    m.cohesion = r.number("cohesion");
  }
  if (m.kind == MaterialKind::Snow) {
    m.critical_compression = r.number("critical_compression");
    m.critical_stretch = r.number("critical_stretch");
    m.hardening = r.number("hardening");
  }
  // The stiffest the material gets: its P-wave modulus, hardened snow included. Past
  // 1e14 Pa (100x diamond) stresses times volumes and squared wave speeds near float's
  // range; the key named is the one that makes it large.
  {
    const double nu = m.poisson_ratio;
    const double ratio = (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
    const double harden =
        m.kind == MaterialKind::Snow ? std::exp(m.hardening * m.critical_compression) : 1.0;
    const double modulus = m.youngs_modulus * ratio * harden;
    if (!(modulus <= 1e14)) {
      const std::string at = harden > ratio ? "hardening"
                             : ratio > 100  ? "poisson_ratio"
                                            : "youngs_modulus";
      fail(r.origin_of(at), r.path_of(at),
           "the material's stiffest modulus E (1 - nu) / ((1 + nu) (1 - 2 nu))" +
               std::string(m.kind == MaterialKind::Snow ? " exp(hardening critical_compression)"
                                                        : "") +
               " is " + fmt3(modulus) + " Pa (E " + fmt_num(m.youngs_modulus) + ", nu " +
               fmt_num(nu) +
               (m.kind == MaterialKind::Snow ? ", hardening factor " + fmt_num(harden) : "") +
               "); at most 1e14 Pa, past any real solid");
    }
  }
  if (r.has("color")) m.color = read_color(r, "color");
  r.finish();
  return m;
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
  if (type == "box") {
    s.kind = ShapeDesc::Kind::Box;
    s.min = r.vec3("min");
    s.max = r.vec3("max");
    require_greater(s.min, s.max, r.origin_of("max"), r.path_of("max"));
  } else if (type == "sphere") {
    s.kind = ShapeDesc::Kind::Sphere;
    s.center = r.vec3("center");
    s.radius = r.number("radius");
  } else if (type == "cylinder") {
    s.kind = ShapeDesc::Kind::Cylinder;
    s.center = r.vec3("center");
    s.axis = r.vec3("axis");
    s.radius = r.number("radius");
    s.height = r.number("height");
  } else if (type == "plane") {
    s.kind = ShapeDesc::Kind::Plane;
    s.point = r.vec3("point");
    s.normal = r.vec3("normal");
  } else {
    SHELLMPM_CHECK(type == "mesh", "shape type " << type);
    s.kind = ShapeDesc::Kind::Mesh;
    std::tie(s.mesh_path, s.mesh_where) = read_mesh_path(r, "path", scene_path);
    s.mesh_scale = r.number("scale");
    s.mesh_translate = r.vec3("translate");
  }
  r.finish();
  return s;
}

ShellMaterialDesc read_shell_material(const DocNode& node, const std::string& path) {
  MapReader r(node, "shell_materials[]", path, false);
  ShellMaterialDesc m;
  m.name = r.string("name");
  m.youngs_modulus = r.number("youngs_modulus");
  m.poisson_ratio = r.number("poisson_ratio");
  m.density = r.number("density");
  m.thickness = r.number("thickness");
  m.yield_stress = r.number("yield_stress");
  m.stretch_limit = r.number("stretch_limit");
  m.damping = r.number("damping");
  m.stiffness_damping = r.number("stiffness_damping");
  m.quadrature_inplane = r.int32("quadrature_inplane");
  if (m.quadrature_inplane != 1 && m.quadrature_inplane != 3 && m.quadrature_inplane != 6 &&
      m.quadrature_inplane != 7) {
    fail(r.origin_of("quadrature_inplane"), r.path_of("quadrature_inplane"),
         "must be one of 1, 3, 6, 7 (points per triangle), got " +
             std::to_string(m.quadrature_inplane));
  }
  m.quadrature_thickness = r.int32("quadrature_thickness");
  m.friction = r.number("friction");
  m.contact_stiffness = r.has("contact_stiffness") ? r.number("contact_stiffness") : 0.0;
  m.contact_shear = r.has("contact_shear") ? r.number("contact_shear") : 0.0;
  m.contact_samples = r.int32("contact_samples");
  if (m.contact_samples != 1 && m.contact_samples != 3 && m.contact_samples != 6 &&
      m.contact_samples != 7) {
    fail(r.origin_of("contact_samples"), r.path_of("contact_samples"),
         "must be one of 1, 3, 6, 7 (contact particles per triangle), got " +
             std::to_string(m.contact_samples));
  }
  if (r.has("front_color")) m.front_color = read_color(r, "front_color");
  if (r.has("back_color")) m.back_color = read_color(r, "back_color");
  r.finish();
  return m;
}

/// Names used in output file names: [A-Za-z0-9_-]+.
bool file_name_safe(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || is_digit(c) || c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

/// Reads the `geometry` block of a shell into `sh`; returns the number of control points of
/// procedural geometry, or -1 for a mesh file (not known before it is loaded).
long long read_shell_geometry(MapReader& shell, ShellDesc& sh, const std::string& scene_path,
                              std::string& type) {
  MapReader g(*shell.block("geometry"), "shells[].geometry", shell.path_of("geometry"), true);
  type = g.choice("type");
  g.check_keys(&type);
  long long n = -1;
  if (type == "sheet") {
    sh.kind = ShellDesc::Kind::Sheet;
    const std::array<double, 2> size = g.vec2("size");
    const std::array<int, 2> res = g.int2("resolution");
    for (int a = 0; a < 2; ++a) {
      sh.size[a] = size[a];
      sh.resolution[a] = res[a];
    }
    n = (res[0] + 1LL) * (res[1] + 1LL);
  } else if (type == "cylinder") {
    sh.kind = ShellDesc::Kind::Cylinder;
    sh.radius = g.number("radius");
    sh.height = g.number("height");
    sh.angle_deg = g.number("angle");
    const std::array<int, 2> res = g.int2("resolution");
    sh.resolution[0] = res[0];
    sh.resolution[1] = res[1];
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
  } else if (type == "sphere") {
    sh.kind = ShellDesc::Kind::Sphere;
    sh.radius = g.number("radius");
    sh.subdivisions = g.int32("subdivisions");
    n = 10LL * (1LL << (2 * sh.subdivisions)) + 2;
  } else {
    SHELLMPM_CHECK(type == "mesh", "shell geometry type " << type);
    sh.kind = ShellDesc::Kind::Mesh;
    std::tie(sh.mesh_path, sh.mesh_where) = read_mesh_path(g, "path", scene_path);
  }
  g.finish();
  return n;
}

/// "index 121 is out of range: the sheet has 121 vertices (0..120)".
std::string index_range_message(long long index, long long num_vertices, const std::string& what) {
  return "index " + std::to_string(index) + " is out of range: " + what + " has " +
         std::to_string(num_vertices) + " vert" + (num_vertices == 1 ? "ex" : "ices") +
         (num_vertices > 0 ? " (0.." + std::to_string(num_vertices - 1) + ")" : "");
}

PinDesc read_pin(const DocNode& node, const std::string& path, const std::string& geometry_type,
                 const std::string& geometry_path, long long num_vertices,
                 const ShotSettings& shot) {
  MapReader r(node, "shells[].pins[]", path, false);
  PinDesc pin;
  const char* selectors[3] = {"indices", "box", "group"};
  std::vector<std::string> given;
  for (const char* sel : selectors)
    if (r.has(sel)) given.push_back(sel);
  if (given.empty()) {
    fail(r.origin(), path, "needs exactly one of indices, box, group (none given)");
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
    if (num_vertices >= 0) {
      const DocNode& list = *r.present("indices");
      for (std::size_t k = 0; k < pin.indices.size(); ++k) {
        if (pin.indices[k] >= num_vertices) {
          fail(list.items[k].origin, r.path_of("indices") + "[" + std::to_string(k) + "]",
               index_range_message(pin.indices[k], num_vertices, "the " + geometry_type));
        }
      }
    }
  } else if (sel == "box") {
    MapReader b(*r.block("box"), "shells[].pins[].box", r.path_of("box"), false);
    pin.has_box = true;
    pin.box_min = b.vec3("min");
    pin.box_max = b.vec3("max");
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
  const std::array<bool, 3> comp = r.bool3("components");
  if (!comp[0] && !comp[1] && !comp[2]) {
    fail(r.origin_of("components"), r.path_of("components"),
         "at least one of x, y, z must be true (held); all false pins nothing");
  }
  for (int a = 0; a < 3; ++a) pin.components[a] = comp[a];
  pin.keyframes = read_keyframes(r, "keyframes", "shells[].pins[].keyframes[]", shot);
  if (r.has("release")) pin.release_time = r.number("release");
  r.finish();
  return pin;
}

ShellDesc read_shell(const DocNode& node, std::size_t i, const Scene& scene,
                     std::map<std::string, std::string>& names) {
  const std::string p = "shells[" + std::to_string(i) + "]";
  MapReader r(node, "shells[]", p, false);
  ShellDesc sh;
  sh.name = r.has("name") ? r.string("name") : "shell" + std::to_string(i);
  if (!file_name_safe(sh.name)) {
    fail(r.origin_of("name"), r.path_of("name"),
         "shell name '" + sh.name +
             "' may hold only letters, digits, '_' and '-' (it is used in output file names)");
  }
  if (!names.emplace(sh.name, p).second) {
    fail(r.origin_of("name"), r.path_of("name"),
         "duplicate shell name '" + sh.name + "' (also " + names[sh.name] + ")");
  }
  const std::string mat = r.string("material");
  auto found = std::find_if(scene.shell_materials.begin(), scene.shell_materials.end(),
                            [&](const ShellMaterialDesc& m) { return m.name == mat; });
  if (found == scene.shell_materials.end()) {
    std::vector<std::string> known;
    for (const ShellMaterialDesc& m : scene.shell_materials) known.push_back(m.name);
    fail(r.origin_of("material"), r.path_of("material"),
         "unknown shell material '" + mat + "' (" +
             (known.empty() ? std::string("no shell_materials are defined")
                            : "shell_materials: " + join(known)) +
             ")");
  }
  sh.material = static_cast<int>(found - scene.shell_materials.begin());
  std::string type;
  const long long n = read_shell_geometry(r, sh, scene.path, type);
  sh.scale = r.number("scale");
  sh.rotate_deg = r.vec3("rotate");
  sh.translate = r.vec3("translate");
  require_in_position_range(sh.translate, scene.shot, r.origin_of("translate"),
                            r.path_of("translate"), "the translation");
  sh.placement_where = where_text(r.origin_of("translate"), r.path_of("translate"));
  {
    // The placed procedural mesh stays finite and near the domain (meshes from files are
    // checked once loaded: io/scene_bounds.h); a shell thicker than its radius has
    // inverted layers.
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
    const double t = scene.shell_materials[sh.material].thickness;
    const bool curved = sh.kind == ShellDesc::Kind::Sphere || sh.kind == ShellDesc::Kind::Cylinder;
    if (curved && !(t < sh.scale * sh.radius)) {
      const DocNode* g = r.present("geometry");
      const DocNode* rad = g && g->kind == DocNode::Kind::Map ? find_entry(*g, "radius") : nullptr;
      fail(rad ? rad->origin : r.origin_of("geometry"), r.path_of("geometry") + ".radius",
           "the shell's radius " + fmt_num(sh.scale * sh.radius) + " m (after scale) is not " +
               "larger than the thickness " + fmt_num(t) + " m of shell material '" +
               scene.shell_materials[sh.material].name +
               "': its inner layers would pass through the axis (a thin shell is much thinner "
               "than its radius)");
    }
  }
  sh.velocity = r.vec3("velocity");
  sh.pressure = r.number("pressure");
  const DocNode& loads = *r.block("point_loads");
  for (std::size_t k = 0; k < loads.items.size(); ++k) {
    const std::string lp = r.path_of("point_loads") + "[" + std::to_string(k) + "]";
    MapReader lr(loads.items[k], "shells[].point_loads[]", lp, false);
    PointLoadDesc load;
    load.index = lr.int32("index");
    load.where = where_text(lr.origin_of("index"), lr.path_of("index"));
    if (n >= 0 && load.index >= n) {
      fail(lr.origin_of("index"), lr.path_of("index"),
           index_range_message(load.index, n, "the " + type));
    }
    load.force = lr.vec3("force");
    lr.finish();
    sh.point_loads.push_back(load);
  }
  const DocNode& pins = *r.block("pins");
  for (std::size_t k = 0; k < pins.items.size(); ++k) {
    sh.pins.push_back(read_pin(pins.items[k], r.path_of("pins") + "[" + std::to_string(k) + "]",
                               type, r.path_of("geometry"), n, scene.shot));
  }
  sh.output_refine = r.int32("output_refine");
  sh.write_mesh = r.boolean("write_mesh");
  {
    const std::string c = r.choice("contact");
    sh.contact = c == "on" ? ShellDesc::Contact::On
                 : c == "off" ? ShellDesc::Contact::Off
                              : ShellDesc::Contact::Auto;
  }
  r.finish();
  return sh;
}

Scene build_scene(const DocNode& root, const std::string& path) {
  Scene scene;
  scene.path = path;
  MapReader top(root, "", "", true);
  top.integer("version");  // first, so a file from another version fails on that alone
  top.check_keys(nullptr);
  read_shot(*top.block("shot"), scene.shot);

  // materials
  std::map<std::string, std::string> material_names;  // name -> path of its first use
  const DocNode& materials = *top.block("materials");
  for (std::size_t i = 0; i < materials.items.size(); ++i) {
    const std::string p = "materials[" + std::to_string(i) + "]";
    MaterialDesc m = read_material(materials.items[i], p);
    if (!material_names.emplace(m.name, p).second) {
      const DocNode* name_node = find_entry(materials.items[i], "name");
      SHELLMPM_CHECK(name_node != nullptr, "no name in " << p);
      fail(name_node->origin, p + ".name",
           "duplicate material name '" + m.name + "' (also " + material_names[m.name] + ")");
    }
    scene.materials.push_back(std::move(m));
  }

  // sources
  std::map<std::string, std::string> source_names;  // name -> path of its first use
  const DocNode& sources = *top.block("sources");
  for (std::size_t i = 0; i < sources.items.size(); ++i) {
    const std::string p = "sources[" + std::to_string(i) + "]";
    MapReader r(sources.items[i], "sources[]", p, false);
    SourceDesc src;
    src.name = r.has("name") ? r.string("name") : "source" + std::to_string(i);
    if (!source_names.emplace(src.name, p).second) {
      fail(r.origin_of("name"), r.path_of("name"),
           "duplicate source name '" + src.name + "' (also " + source_names[src.name] + ")");
    }
    const std::string mat = r.string("material");
    auto found = std::find_if(scene.materials.begin(), scene.materials.end(),
                              [&](const MaterialDesc& m) { return m.name == mat; });
    if (found == scene.materials.end()) {
      std::vector<std::string> names;
      for (const MaterialDesc& m : scene.materials) names.push_back(m.name);
      fail(r.origin_of("material"), r.path_of("material"),
           "unknown material '" + mat + "' (" +
               (names.empty() ? std::string("no materials are defined")
                              : "materials: " + join(names)) +
               ")");
    }
    src.material = static_cast<int>(found - scene.materials.begin());
    src.shape = read_shape(*r.block("shape"), r.path_of("shape"), true, path);
    src.shape.where = where_text(r.origin_of("shape"), r.path_of("shape"));
    src.particles_per_cell = r.number("particles_per_cell");
    src.velocity = r.vec3("velocity");
    src.seed = static_cast<unsigned>(r.integer("seed"));
    if (const DocNode* emit = r.block("emit")) {
      MapReader e(*emit, "sources[].emit", r.path_of("emit"), false);
      std::tie(src.emit_start, src.emit_end) = e.frames("frames");
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
  }

  // colliders
  std::map<std::string, std::string> collider_names;
  const DocNode& colliders = *top.block("colliders");
  for (std::size_t i = 0; i < colliders.items.size(); ++i) {
    const std::string p = "colliders[" + std::to_string(i) + "]";
    MapReader r(colliders.items[i], "colliders[]", p, false);
    ColliderDesc c;
    c.name = r.has("name") ? r.string("name") : "collider" + std::to_string(i);
    if (!collider_names.emplace(c.name, p).second) {
      fail(r.origin_of("name"), r.path_of("name"),
           "duplicate collider name '" + c.name + "' (also " + collider_names[c.name] + ")");
    }
    c.shape = read_shape(*r.block("shape"), r.path_of("shape"), false, path);
    if (c.shape.kind == ShapeDesc::Kind::Plane) {
      require_in_position_range(c.shape.point, scene.shot, r.origin_of("shape"),
                                r.path_of("shape") + ".point", "the plane's point");
    } else if (c.shape.kind != ShapeDesc::Kind::Mesh) {  // meshes: once loaded (scene_bounds)
      const Aabb b = shape_bounds(c.shape);
      for (const Vec3d& corner : {b.lo, b.hi})
        require_in_position_range(corner, scene.shot, r.origin_of("shape"), r.path_of("shape"),
                                  "the collider");
    }
    const std::string boundary = r.choice("boundary");
    c.boundary = boundary == "sticky" ? BoundaryKind::Sticky
                 : boundary == "slip" ? BoundaryKind::Slip
                                      : BoundaryKind::Separate;
    c.friction = r.number("friction");
    c.keyframes = read_keyframes(r, "keyframes", "colliders[].keyframes[]", scene.shot);
    r.finish();
    scene.colliders.push_back(std::move(c));
  }

  // shell materials
  std::map<std::string, std::string> shell_material_names;  // name -> path of its first use
  const DocNode& shell_materials = *top.block("shell_materials");
  for (std::size_t i = 0; i < shell_materials.items.size(); ++i) {
    const std::string p = "shell_materials[" + std::to_string(i) + "]";
    ShellMaterialDesc m = read_shell_material(shell_materials.items[i], p);
    if (!shell_material_names.emplace(m.name, p).second) {
      const DocNode* name_node = find_entry(shell_materials.items[i], "name");
      SHELLMPM_CHECK(name_node != nullptr, "no name in " << p);
      fail(name_node->origin, p + ".name",
           "duplicate shell material name '" + m.name + "' (also " + shell_material_names[m.name] +
               ")");
    }
    scene.shell_materials.push_back(std::move(m));
  }

  // shells
  std::map<std::string, std::string> shell_names;  // name -> path of its first use
  const DocNode& shells = *top.block("shells");
  for (std::size_t i = 0; i < shells.items.size(); ++i) {
    scene.shells.push_back(read_shell(shells.items[i], i, scene, shell_names));
  }

  // pre-roll
  {
    MapReader r(*top.block("preroll"), "preroll", "preroll", false);
    scene.preroll.enabled = r.boolean("enabled");
    scene.preroll.method = r.choice("method") == "dynamic" ? PrerollSettings::Method::Dynamic
                                                          : PrerollSettings::Method::Static;
    scene.preroll.tolerance = r.number("tolerance");
    scene.preroll.max_steps = r.int32("max_steps");
    r.finish();
  }

  // output
  {
    MapReader r(*top.block("output"), "output", "output", false);
    OutputSettings& o = scene.output;
    o.directory = r.string("directory");
    o.density = r.boolean("density");
    o.density_pattern = r.string("density_pattern");
    require_one_hash_run(o.density_pattern, r.origin_of("density_pattern"),
                         r.path_of("density_pattern"));
    require_output_file(o.density_pattern, true, r.origin_of("density_pattern"),
                        r.path_of("density_pattern"));
    o.velocity = r.boolean("velocity");
    o.half_float = r.boolean("half_float");
    o.voxel_size = r.number("voxel_size");
    if (o.voxel_size > 0 &&
        !(o.voxel_size >= scene.shot.dx / 8 && o.voxel_size <= 16 * scene.shot.dx)) {
      fail(r.origin_of("voxel_size"), r.path_of("voxel_size"),
           "must be 0 (= shot.dx) or between dx/8 and 16 dx (" + fmt_num(scene.shot.dx / 8) +
               " .. " + fmt_num(16 * scene.shot.dx) + " m), got " + fmt_num(o.voxel_size) +
               " (a finer volume only resamples the same particles, at up to 512x the memory)");
    }
    o.particles = r.boolean("particles");
    o.particles_pattern = r.string("particles_pattern");
    require_one_hash_run(o.particles_pattern, r.origin_of("particles_pattern"),
                         r.path_of("particles_pattern"));
    require_output_file(o.particles_pattern, true, r.origin_of("particles_pattern"),
                        r.path_of("particles_pattern"));
    o.stats_file = r.string("stats");
    require_output_file(o.stats_file, false, r.origin_of("stats"), r.path_of("stats"));
    o.checkpoint_every = r.int32("checkpoint_every");
    // The format first: the default pattern's extension follows it, and a given pattern
    // must not name another format (a glTF file called .ply misleads every importer).
    o.shell_format = r.choice("shell_format");
    const std::string ext = std::string(".") + o.shell_format;
    if (r.has("shell_pattern")) {
      o.shell_pattern = r.string("shell_pattern");
      const bool ends_in_ext =
          o.shell_pattern.size() >= ext.size() &&
          o.shell_pattern.compare(o.shell_pattern.size() - ext.size(), ext.size(), ext) == 0;
      if (!ends_in_ext) {
        fail(r.origin_of("shell_pattern"), r.path_of("shell_pattern"),
             "must end in '" + ext + "' for output.shell_format " + o.shell_format + ", got '" +
                 o.shell_pattern + "' (leave shell_pattern out for \"{name}.####" + ext +
                 "\", or set shell_format to match)");
      }
    } else {
      o.shell_pattern = "{name}.####" + ext;
    }
    require_one_hash_run(o.shell_pattern, r.origin_of("shell_pattern"), r.path_of("shell_pattern"));
    require_output_file(o.shell_pattern, true, r.origin_of("shell_pattern"),
                        r.path_of("shell_pattern"));
    if (scene.shells.size() > 1 && o.shell_pattern.find("{name}") == std::string::npos) {
      fail(r.origin_of("shell_pattern"), r.path_of("shell_pattern"),
           "must contain {name} (the shell's name) when there is more than one shell (there are " +
               std::to_string(scene.shells.size()) + "), got '" + o.shell_pattern + "'");
    }
    r.finish();
  }
  read_render(*top.block("render"), scene.render);
  top.finish();
  return scene;
}

}  // namespace

// ------------------------------------------------------------------------------------------
// Public
// ------------------------------------------------------------------------------------------

std::string KeySpec::type_text() const {
  switch (type) {
    case KeyType::Int:
      return "integer";
    case KeyType::Number:
      return "number";
    case KeyType::Bool:
      return "boolean";
    case KeyType::String:
      return "string";
    case KeyType::Enum:
      return "enum";
    case KeyType::Vec3:
      return "vec3";
    case KeyType::Vec2:
      return "vec2";
    case KeyType::Int2:
      return "int2";
    case KeyType::IntList:
      return "integer list";
    case KeyType::Bool3:
      return "bool3";
    case KeyType::FrameRange:
      return "frame range";
    case KeyType::Map:
      return "mapping";
    case KeyType::List:
      return "list";
    case KeyType::Shape:
      return "shape";
  }
  return "?";
}

std::string KeySpec::unit_text() const {
  return unit.empty() ? "-" : unit;
}

std::string KeySpec::default_text() const {
  switch (presence) {
    case Presence::Required:
      return "required";
    case Presence::Default:
      return "`" + default_value + "`";
    case Presence::Optional:
      return default_value;
  }
  return "?";
}

std::string KeySpec::range_text() const {
  std::vector<std::string> parts;
  if (type == KeyType::FrameRange) {
    parts.push_back("first " + bounds_text(*this) + ", last >= first");
  } else if (!bounds_text(*this).empty()) {
    parts.push_back(bounds_text(*this));
  }
  if (!choices.empty()) parts.push_back("one of: " + join(choices));
  if (nonempty) parts.push_back("non-empty");
  if (unit_vector) parts.push_back("nonzero; normalized");
  if (!rule.empty()) parts.push_back(rule);
  return parts.empty() ? "-" : join(parts, "; ");
}

std::string KeySpec::only_for_text() const {
  return only_for.empty() ? "-" : join(only_for);
}

const std::vector<KeySpec>& scene_schema() {
  static const std::vector<KeySpec> schema = build_schema();
  return schema;
}

void check_shell_indices(const ShellDesc& shell, int num_vertices, const std::string& scene_path) {
  SHELLMPM_CHECK(num_vertices >= 0, "num_vertices " << num_vertices);
  const std::string what = "the mesh of shell '" + shell.name + "'";
  for (std::size_t j = 0; j < shell.pins.size(); ++j) {
    const PinDesc& pin = shell.pins[j];
    for (std::size_t k = 0; k < pin.indices.size(); ++k) {
      if (pin.indices[k] >= 0 && pin.indices[k] < num_vertices) continue;
      const std::string fallback =
          "shell '" + shell.name + "' pins[" + std::to_string(j) + "].indices";
      throw error_at_where(pin.where, scene_path, fallback, "[" + std::to_string(k) + "]",
                           index_range_message(pin.indices[k], num_vertices, what));
    }
  }
  for (std::size_t j = 0; j < shell.point_loads.size(); ++j) {
    const PointLoadDesc& load = shell.point_loads[j];
    if (load.index >= 0 && load.index < num_vertices) continue;
    const std::string fallback =
        "shell '" + shell.name + "' point_loads[" + std::to_string(j) + "].index";
    throw error_at_where(load.where, scene_path, fallback, "",
                         index_range_message(load.index, num_vertices, what));
  }
}

Scene parse_scene(const std::string& text, const std::string& path,
                  const std::vector<std::string>& overrides) {
  // Every string of the scene can reach stats.json and run.json (names, the scene text),
  // which are UTF-8: text that is not is refused here, for check and run alike.
  if (const std::size_t bad = first_invalid_utf8(text); bad != std::string::npos) {
    const Utf8Error e = locate_utf8_error(text, bad);
    throw UserError(path, e.line, "",
                    "not valid UTF-8: byte " + e.byte_hex + " at column " +
                        std::to_string(e.column) +
                        " (the key is not known: the line cannot be decoded). Scene files "
                        "are UTF-8; a Latin-1 accent, for example, is one byte such as 0xE9. "
                        "Convert the file, e.g. iconv -f latin1 -t utf-8");
  }
  for (const std::string& ov : overrides) {
    if (const std::size_t bad = first_invalid_utf8(ov); bad != std::string::npos) {
      const std::size_t eq = ov.find('=');
      const std::string key = eq == std::string::npos ? "" : ov.substr(0, eq);
      const bool in_key = eq == std::string::npos || bad < eq;
      throw UserError("--set", 0, in_key ? "" : key,
                      "not valid UTF-8: byte " + locate_utf8_error(ov, bad).byte_hex + " at " +
                          "character " + std::to_string(bad + 1) + " of the override" +
                          (in_key ? " (in its key)" : "") + "; scene values are UTF-8 text");
    }
  }
  DocNode root = convert(load_yaml(text, path, "", true), path, true, 0, "");
  if (root.kind == DocNode::Kind::Null) {
    throw UserError(path, 0, "", "the scene is empty; it needs at least 'version: 1' and 'shot'");
  }
  if (root.kind != DocNode::Kind::Map) {
    fail(root.origin, "", "expected a mapping of keys at the top level, got " + describe(root));
  }
  for (const std::string& ov : overrides) apply_override(root, ov);
  return build_scene(root, path);
}

Scene read_scene(const std::string& path, const std::vector<std::string>& overrides) {
  std::error_code abs_ec;
  const std::string absolute = fs::absolute(path, abs_ec).lexically_normal().string();
  if (first_invalid_utf8(path) != std::string::npos ||
      first_invalid_utf8(absolute) != std::string::npos) {
    throw UserError(path, 0, "",
                    "the scene file's path is not valid UTF-8; it is written to stats.json "
                    "and run.json, which are UTF-8: rename the file or its folder");
  }
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw UserError(path, 0, "", "is a directory, not a scene file");
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw UserError(path, 0, "", std::string("cannot open scene file: ") + std::strerror(errno));
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw UserError(path, 0, "", "cannot read scene file");
  return parse_scene(text.str(), path, overrides);
}

}  // namespace shellmpm

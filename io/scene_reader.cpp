// Scene file reader: YAML/JSON -> a document tree whose values keep their file and line, or
// the --set override they came from (io/scene_document.h) -> overrides applied
// (io/scene_overrides.h) -> read into a Scene block by block against the schema
// (io/scene_schema.h; the blocks: this file and io/scene_sections.h). The schema binds
// most keys to their fields, so the schema, the reader and docs/scene-format.md cannot
// drift.
#include "io/scene_reader.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/number_text.h"
#include "io/scene_checks.h"
#include "io/scene_overrides.h"
#include "io/scene_quality.h"
#include "io/scene_sections.h"
#include "io/utf8.h"
#include "sim/core/check.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {
namespace {

namespace fs = std::filesystem;
using namespace scenefile;  // NOLINT: this file is the reader's front

/// dt_max >= dt_min, and the steps a frame may take at dt_min bounded (a bound on the work
/// of a frame).
void check_shot_timing(const MapReader& r, const ShotSettings& shot) {
  if (shot.dt_max < shot.dt_min) {
    const std::string at = r.has("dt_max") ? "dt_max" : "dt_min";
    fail(r.origin_of(at), r.path_of(at),
         "dt_max (" + fmt_num(shot.dt_max) + ") must be >= dt_min (" + fmt_num(shot.dt_min) + ")");
  }
  const double steps = 1.0 / (shot.fps * shot.dt_min);
  if (steps <= kMaxStepsPerFrame) return;
  // Name what the user wrote; with both, dt_min when it is below its default.
  const bool small_dt_min = r.has("dt_min") && shot.dt_min < 1e-6;
  const std::string at = r.has("fps") && !small_dt_min ? "fps" : r.has("dt_min") ? "dt_min" : "fps";
  fail(r.origin_of(at), r.path_of(at),
       "a frame (1 / fps = " + fmt3(1.0 / shot.fps) + " s) may take up to " +
           fmt_bound(std::ceil(steps)) + " steps of dt_min = " + fmt_num(shot.dt_min) +
           " s (at most 1e7: such a run would seem to hang); raise shot.fps or shot.dt_min");
}

/// The domain's corners ordered, within the position range (float resolves 1/64 cell
/// there), and at most 2^20 cells per axis.
void check_shot_domain(const MapReader& r, const MapReader& d, const ShotSettings& shot) {
  require_greater(shot.domain_min, shot.domain_max, d.origin_of("max"), d.path_of("max"));
  const double range = kPositionRangeCells * shot.dx;
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
  constexpr double kMaxCells = 1 << 20;
  for (int a = 0; a < 3; ++a) {
    const double cells = (shot.domain_max[a] - shot.domain_min[a]) / shot.dx;
    if (cells > kMaxCells) {
      fail(r.origin_of("dx"), r.path_of("dx"),
           "the domain is " + fmt_num(std::ceil(cells)) + " cells along " + kAxis[a] +
               " (at most 2^20 = 1048576); use a larger dx or a smaller domain");
    }
  }
}

void read_shot(const DocNode& node, ShotSettings& shot) {
  MapReader r(node, "shot", "shot", false);
  r.fill(shot);
  MapReader d(*r.block("domain"), "shot.domain", "shot.domain", false);
  d.fill(shot);
  d.finish();
  // The implicit integrator's steps are bounded by motion and the frame, not by dt_max's
  // explicit default: unless given, dt_max is one frame there.
  shot.dt_max_set = r.has("dt_max");
  if (shot.integrator == Integrator::Implicit && !shot.dt_max_set) shot.dt_max = 1.0 / shot.fps;
  check_shot_timing(r, shot);
  check_shot_domain(r, d, shot);
  r.finish();
}

void read_preroll(const DocNode& node, PrerollSettings& preroll) {
  MapReader r(node, "preroll", "preroll", false);
  r.fill(preroll);
  r.finish();
}

/// A file pattern: one '#' run, a file inside output.directory.
void check_pattern(const MapReader& r, const std::string& key, const std::string& pattern) {
  require_one_hash_run(pattern, r.origin_of(key), r.path_of(key));
  require_output_file(pattern, true, r.origin_of(key), r.path_of(key));
}

/// The shell mesh pattern: its default follows the format, and a given pattern must not
/// name another format (a glTF file called .ply misleads every importer).
void read_shell_pattern(MapReader& r, OutputSettings& o, std::size_t num_shells) {
  const std::string ext = "." + word_of(o.shell_format);
  if (r.has("shell_pattern")) {
    o.shell_pattern = r.string("shell_pattern");
    const bool ends_in_ext =
        o.shell_pattern.size() >= ext.size() &&
        o.shell_pattern.compare(o.shell_pattern.size() - ext.size(), ext.size(), ext) == 0;
    if (!ends_in_ext) {
      fail(r.origin_of("shell_pattern"), r.path_of("shell_pattern"),
           "must end in '" + ext + "' for output.shell_format " + word_of(o.shell_format) +
               ", got '" + o.shell_pattern + "' (leave shell_pattern out for \"{name}.####" + ext +
               "\", or set shell_format to match)");
    }
  } else {
    o.shell_pattern = "{name}.####" + ext;
  }
  check_pattern(r, "shell_pattern", o.shell_pattern);
  if (num_shells > 1 && o.shell_pattern.find("{name}") == std::string::npos) {
    fail(r.origin_of("shell_pattern"), r.path_of("shell_pattern"),
         "must contain {name} (the shell's name) when there is more than one shell (there are " +
             std::to_string(num_shells) + "), got '" + o.shell_pattern + "'");
  }
}

void read_output(const DocNode& node, const Scene& scene, OutputSettings& o) {
  MapReader r(node, "output", "output", false);
  r.fill(o);
  check_pattern(r, "density_pattern", o.density_pattern);
  if (o.voxel_size > 0 &&
      !(o.voxel_size >= scene.shot.dx / 8 && o.voxel_size <= 16 * scene.shot.dx)) {
    fail(r.origin_of("voxel_size"), r.path_of("voxel_size"),
         "must be 0 (= shot.dx) or between dx/8 and 16 dx (" + fmt_num(scene.shot.dx / 8) + " .. " +
             fmt_num(16 * scene.shot.dx) + " m), got " + fmt_num(o.voxel_size) +
             " (a finer volume only resamples the same particles, at up to 512x the memory)");
  }
  check_pattern(r, "particles_pattern", o.particles_pattern);
  require_output_file(o.stats_file, false, r.origin_of("stats"), r.path_of("stats"));
  read_shell_pattern(r, o, scene.shells.size());
  r.finish();
}

void read_cameras(MapReader& r, RenderSettings& rs) {
  NameSet names("camera");
  r.each("cameras", false, [&](MapReader& c, std::size_t) {
    RenderCamera cam;
    c.fill(cam);
    if (cam.name == "auto") {
      fail(c.origin_of("name"), c.path_of("name"),
           "'auto' is the automatic camera's name; choose another name");
    }
    names.add(cam.name, c.path(), c.origin_of("name"), c.path_of("name"));
    const Vec3d view = cam.target - cam.position;
    if (!(view.norm() > 0.0)) {
      fail(c.origin_of("target"), c.path_of("target"), "must differ from position");
    }
    if (view.normalized().cross(cam.up).norm() < 1e-6) {
      fail(c.origin_of("up"), c.path_of("up"),
           "must not be parallel to the view direction (target - position)");
    }
    c.finish();
    rs.cameras.push_back(cam);
  });
  if (!r.has("camera")) return;
  rs.camera = r.string("camera");
  std::vector<std::string> names_known{"auto"};
  for (const RenderCamera& c : rs.cameras) names_known.push_back(c.name);
  if (std::find(names_known.begin(), names_known.end(), rs.camera) == names_known.end()) {
    fail(r.origin_of("camera"), r.path_of("camera"),
         "unknown camera '" + rs.camera + "' (cameras: " + join(names_known) + ")");
  }
}

/// A bulk drawing that needs a cache the run does not write (only with bulk material).
void check_bulk_drawing(const MapReader& r, const Scene& scene, const RenderSettings& rs) {
  if (scene.sources.empty()) return;
  const bool volume = rs.bulk == BulkDraw::Volume || rs.bulk == BulkDraw::Surface;
  if (volume && !scene.output.density) {
    fail(r.origin_of("bulk"), r.path_of("bulk"),
         "'" + word_of(rs.bulk) +
             "' draws the density volume, but the run writes none (output.density: false)");
  }
  if (rs.bulk == BulkDraw::Particles && !scene.output.particles) {
    fail(r.origin_of("bulk"), r.path_of("bulk"),
         "'particles' draws the particle cache, but the run writes none (set output.particles: "
         "true)");
  }
}

void read_render(const DocNode& node, const Scene& scene, RenderSettings& rs) {
  MapReader r(node, "render", "render", false);
  r.fill(rs);
  read_cameras(r, rs);
  check_pattern(r, "pattern", rs.pattern);
  if (rs.pattern.size() < 4 || rs.pattern.compare(rs.pattern.size() - 4, 4, ".png") != 0) {
    fail(r.origin_of("pattern"), r.path_of("pattern"),
         "must end in .png, got '" + rs.pattern + "'");
  }
  check_bulk_drawing(r, scene, rs);
  r.finish();
}

Scene build_scene(const DocNode& root, const std::string& path) {
  Scene scene;
  scene.path = path;
  MapReader top(root, "", "", true);
  top.integer("version");  // first, so a file from another version fails on that alone
  top.check_keys(nullptr);
  read_shot(*top.block("shot"), scene.shot);
  read_materials(top, scene);
  read_sources(top, scene);
  read_colliders(top, scene);
  read_shell_materials(top, scene);
  read_shells(top, scene);
  read_preroll(*top.block("preroll"), scene.preroll);
  read_output(*top.block("output"), scene, scene.output);
  read_render(*top.block("render"), scene, scene.render);
  top.finish();
  return scene;
}

}  // namespace

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
  DocNode root = load_document(text, path, "", true);
  if (root.kind == DocNode::Kind::Null) {
    throw UserError(path, 0, "", "the scene is empty; it needs at least 'version: 1' and 'shot'");
  }
  if (root.kind != DocNode::Kind::Map) {
    fail(root.origin, "", "expected a mapping of keys at the top level, got " + describe(root));
  }
  for (const std::string& ov : overrides) apply_override(root, ov);
  apply_quality(root);
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

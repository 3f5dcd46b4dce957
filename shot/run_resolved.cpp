#include "shot/run_resolved.h"

#include <string>

#include "io/shell_mesh_writer.h"
#include "sim/scene/scene_words.h"

namespace shellmpm {

namespace {

nlohmann::json vec3(const Vec3d& v) {
  return nlohmann::json::array({v.x(), v.y(), v.z()});
}

/// The shell's own mesh pattern: output.shell_pattern with {name} filled in (as the shot
/// runner writes it).
std::string shell_pattern(const OutputSettings& o, const std::string& name) {
  std::string pattern = o.shell_pattern;
  const auto at = pattern.find("{name}");
  if (at != std::string::npos) pattern.replace(at, 6, name);
  return pattern;
}

}  // namespace

nlohmann::json resolved_run_settings(const Scene& scene) {
  const OutputSettings& o = scene.output;
  const RenderSettings& rs = scene.render;
  nlohmann::json j;
  j["fps"] = scene.shot.fps;
  j["frames"] = {scene.shot.frame_start, scene.shot.frame_end};
  j["up_axis"] = word_of(scene.output.up_axis);
  j["units"] = scene.shot.units;
  j["size"] = {rs.width, rs.height};
  const bool bulk = !scene.sources.empty();
  if (o.density && bulk) {
    j["density"] = {{"pattern", o.density_pattern},
                    {"grid", "density"},
                    {"velocity_grid", o.velocity ? nlohmann::json("vel") : nlohmann::json()},
                    {"extinction", rs.volume_extinction}};
  } else {
    j["density"] = nullptr;
  }
  j["particles"] =
      o.particles && bulk ? nlohmann::json{{"pattern", o.particles_pattern}} : nlohmann::json();
  nlohmann::json shells = nlohmann::json::array();
  for (const ShellDesc& sh : scene.shells) {
    if (!sh.write_mesh) continue;
    const ShellMaterialDesc* mat =
        sh.material >= 0 && static_cast<std::size_t>(sh.material) < scene.shell_materials.size()
            ? &scene.shell_materials[sh.material]
            : nullptr;
    const Vec3d front = mat && mat->front_color ? *mat->front_color : rs.shell_front;
    const Vec3d back = mat && mat->back_color ? *mat->back_color : rs.shell_back;
    shells.push_back({{"name", sh.name},
                      {"pattern", shell_pattern(o, sh.name)},
                      {"format", mesh_format_extension(o.shell_format)},
                      {"front_color", vec3(front)},
                      {"back_color", vec3(back)}});
  }
  j["shells"] = shells;
  nlohmann::json cameras = nlohmann::json::array();
  for (const RenderCamera& c : rs.cameras)
    cameras.push_back({{"name", c.name},
                       {"position", vec3(c.position)},
                       {"target", vec3(c.target)},
                       {"up", vec3(c.up)},
                       {"fov", c.fov_deg}});
  j["cameras"] = cameras;
  j["camera"] = !rs.camera.empty() ? rs.camera : rs.cameras.empty() ? "auto" : rs.cameras[0].name;
  j["domain"] = {{"min", vec3(scene.shot.domain_min)}, {"max", vec3(scene.shot.domain_max)}};
  return j;
}

}  // namespace shellmpm

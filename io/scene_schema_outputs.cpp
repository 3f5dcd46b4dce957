// The scene format's table, output part: pre-roll, outputs, previews, and the shapes of
// sources and colliders (io/scene_schema_parts.h).
#include <string>
#include <vector>

#include "io/scene_schema_parts.h"
#include "io/scene_spec.h"
#include "sim/scene/scene.h"

namespace shellmpm::scenefile {

std::vector<KeySpec> output_keys() {
  using T = KeyType;
  return {
      // pre-roll
      Spec("preroll.enabled", T::Bool).to(&PrerollSettings::enabled).def("false"),
      Spec("preroll.method", T::Enum).to(&PrerollSettings::method).def("static"),
      Spec("preroll.tolerance", T::Number).to(&PrerollSettings::tolerance).def("1e-4").gt(0),
      Spec("preroll.max_steps", T::Int).to(&PrerollSettings::max_steps).def("200000").ge(1),
      // output
      Spec("output.directory", T::String).to(&OutputSettings::directory).def("out").nonempty(),
      Spec("output.density", T::Bool).to(&OutputSettings::density).def("true"),
      Spec("output.density_pattern", T::String)
          .to(&OutputSettings::density_pattern)
          .def("density.####.vdb")
          .rule(std::string("exactly one run of `#`; ") + kOutputFile),
      Spec("output.velocity", T::Bool).to(&OutputSettings::velocity).def("false"),
      Spec("output.half_float", T::Bool).to(&OutputSettings::half_float).def("false"),
      Spec("output.voxel_size", T::Number)
          .to(&OutputSettings::voxel_size)
          .def("0")
          .unit("m")
          .ge(0)
          .rule("0 or in [dx/8, 16 dx]"),
      Spec("output.particles", T::Bool).to(&OutputSettings::particles).def("false"),
      Spec("output.particles_pattern", T::String)
          .to(&OutputSettings::particles_pattern)
          .def("particles.####.ply")
          .rule(std::string("exactly one run of `#`; ") + kOutputFile),
      Spec("output.stats", T::String)
          .to(&OutputSettings::stats_file)
          .def("stats.json")
          .nonempty()
          .rule(kOutputFile),
      Spec("output.checkpoint_every", T::Int).to(&OutputSettings::checkpoint_every).def("0").ge(0),
      Spec("output.shell_pattern", T::String)
          .optional("`\"{name}.####.ply\"`, `.obj` or `.glb` as `shell_format` says")
          .rule(std::string("exactly one run of `#`; contains `{name}` when there are several "
                            "shells; ends in `.ply`, `.obj` or `.glb` as `shell_format` says; ") +
                kOutputFile),
      Spec("output.shell_format", T::Enum).to(&OutputSettings::shell_format).def("ply"),
      Spec("output.up_axis", T::Enum).to(&OutputSettings::up_axis).def("y"),
      // render (previews; nothing here changes the simulation)
      Spec("render.preview", T::Bool).to(&RenderSettings::preview).def("false"),
      Spec("render.renderer", T::Enum).to(&RenderSettings::renderer).def("raster"),
      Spec("render.size", T::Int2)
          .to(&RenderSettings::width, &RenderSettings::height)
          .def("[960, 540]")
          .ge(16)
          .le(8192),
      Spec("render.camera", T::String)
          .optional("the first of `cameras`, else `auto`")
          .nonempty()
          .rule("`auto` or a name in cameras"),
      Spec("render.cameras", T::List).def("[]"),
      Spec("render.cameras[].name", T::String)
          .to(&RenderCamera::name)
          .required()
          .nonempty()
          .rule("unique; not `auto`"),
      Spec("render.cameras[].position", T::Vec3).to(&RenderCamera::position).required().unit("m"),
      Spec("render.cameras[].target", T::Vec3)
          .to(&RenderCamera::target)
          .required()
          .unit("m")
          .rule("not at position"),
      Spec("render.cameras[].up", T::Vec3)
          .to(&RenderCamera::up)
          .def("[0, 1, 0]")
          .unit_vector()
          .rule("not along the view direction"),
      Spec("render.cameras[].fov", T::Number)
          .to(&RenderCamera::fov_deg)
          .def("40")
          .unit("deg")
          .gt(0)
          .lt(180),
      Spec("render.samples", T::Int).to(&RenderSettings::samples).def("4").ge(1).le(256),
      Spec("render.ao_samples", T::Int).to(&RenderSettings::ao_samples).def("2").ge(0).le(64),
      Spec("render.bulk", T::Enum).to(&RenderSettings::bulk).def("auto"),
      Spec("render.volume_extinction", T::Number)
          .to(&RenderSettings::volume_extinction)
          .def("250")
          .unit("1/m")
          .gt(0),
      Spec("render.iso_value", T::Number).to(&RenderSettings::iso_value).def("0.5").gt(0),
      Spec("render.particle_radius", T::Number)
          .to(&RenderSettings::particle_radius)
          .optional("half the particle spacing of the first source")
          .unit("m")
          .gt(0),
      Spec("render.ground", T::Bool).to(&RenderSettings::ground).def("true"),
      Spec("render.key_light", T::Vec3)
          .to(&RenderSettings::key_light)
          .optional("above and beside the camera")
          .unit_vector()
          .rule("points towards the light"),
      Spec("render.shell_front", T::Vec3)
          .to(&RenderSettings::shell_front)
          .def("[0.8, 0.3, 0.2]")
          .color(),
      Spec("render.shell_back", T::Vec3)
          .to(&RenderSettings::shell_back)
          .def("[0.2, 0.42, 0.8]")
          .color(),
      Spec("render.collider_color", T::Vec3)
          .to(&RenderSettings::collider_color)
          .def("[0.45, 0.45, 0.48]")
          .color(),
      Spec("render.ground_color", T::Vec3)
          .to(&RenderSettings::ground_color)
          .def("[0.5, 0.5, 0.48]")
          .color(),
      Spec("render.pattern", T::String)
          .to(&RenderSettings::pattern)
          .def("preview.####.png")
          .rule(std::string("exactly one run of `#`; ends in .png; ") + kOutputFile),
      Spec("render.contact_sheet", T::Bool).to(&RenderSettings::contact_sheet).def("true"),
      Spec("render.movie", T::Bool).to(&RenderSettings::movie).def("true"),
      // shapes (the value of sources[].shape and colliders[].shape)
      Spec("shape.type", T::Enum).to(&ShapeDesc::kind).required(),
      Spec("shape.min", T::Vec3).to(&ShapeDesc::min).required().unit("m").only_for({"box"}),
      Spec("shape.max", T::Vec3)
          .to(&ShapeDesc::max)
          .required()
          .unit("m")
          .only_for({"box"})
          .rule("> min on every axis"),
      Spec("shape.center", T::Vec3)
          .to(&ShapeDesc::center)
          .required()
          .unit("m")
          .only_for({"sphere", "cylinder"}),
      Spec("shape.radius", T::Number)
          .to(&ShapeDesc::radius)
          .required()
          .unit("m")
          .gt(0)
          .only_for({"sphere", "cylinder"}),
      Spec("shape.axis", T::Vec3)
          .to(&ShapeDesc::axis)
          .required()
          .unit_vector()
          .only_for({"cylinder"}),
      Spec("shape.height", T::Number)
          .to(&ShapeDesc::height)
          .required()
          .unit("m")
          .gt(0)
          .only_for({"cylinder"}),
      Spec("shape.point", T::Vec3).to(&ShapeDesc::point).required().unit("m").only_for({"plane"}),
      Spec("shape.normal", T::Vec3)
          .to(&ShapeDesc::normal)
          .required()
          .unit_vector()
          .only_for({"plane"}),
      Spec("shape.path", T::String)
          .required()
          .nonempty()
          .only_for({"mesh"})
          .rule("readable file; relative to the scene file"),
      Spec("shape.scale", T::Number)
          .to(&ShapeDesc::mesh_scale)
          .def("1")
          .ge(1e-6)
          .le(1e6)
          .only_for({"mesh"}),
      Spec("shape.translate", T::Vec3)
          .to(&ShapeDesc::mesh_translate)
          .def("[0, 0, 0]")
          .unit("m")
          .only_for({"mesh"}),
  };
}

}  // namespace shellmpm::scenefile

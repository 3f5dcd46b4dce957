// The scene format, one row per key: io/scene_schema.h says what a row holds, and
// docs/scene-format.md shows this table (a test keeps the two equal).
#include <string>
#include <vector>

#include "io/scene_spec.h"
#include "sim/scene/scene.h"

namespace shellmpm::scenefile {
namespace {

using T = KeyType;

/// Position keys that place simulated things off the grid (keyframes, collider shapes):
/// within the range where Real resolves 1/64 of a cell (see kPositionRangeCells).
const char* const kInPositionRange = "each coordinate within 2^17 dx of the origin";
/// Output file names (patterns, stats): inside output.directory.
const char* const kOutputFile = "a relative file name; its folders are created";

/// The keys of one keyframe list item under `prefix` ("colliders[].keyframes[]").
std::vector<KeySpec> keyframe_specs(const std::string& prefix) {
  return {
      Spec(prefix + ".time", T::Number).optional("give time or frame").unit("s").ge(0),
      Spec(prefix + ".frame", T::Int).optional("give time or frame").ge(1),
      Spec(prefix + ".translate", T::Vec3)
          .to(&Keyframe::translate)
          .def("[0, 0, 0]")
          .unit("m")
          .rule(kInPositionRange),
      Spec(prefix + ".rotate", T::Vec3).to(&Keyframe::rotate_deg).def("[0, 0, 0]").unit("deg"),
  };
}

}  // namespace

std::vector<KeySpec> build_schema() {
  std::vector<KeySpec> schema;
  auto add = [&schema](std::vector<KeySpec> specs) {
    schema.insert(schema.end(), specs.begin(), specs.end());
  };
  const std::string kPinSelector = "give exactly one of indices, box, group";
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
      Spec("shot.frames", T::FrameRange)
          .to(&ShotSettings::frame_start, &ShotSettings::frame_end)
          .def("[1, 48]")
          .ge(1)
          .le(999999999),  // = kMaxFrameNumber
      Spec("shot.fps", T::Number).to(&ShotSettings::fps).def("24").unit("1/s").ge(0.01).le(1e5),
      Spec("shot.cfl", T::Number).to(&ShotSettings::cfl).def("0.3").gt(0).le(1),
      Spec("shot.dt_min", T::Number)
          .to(&ShotSettings::dt_min)
          .def("1e-6")
          .unit("s")
          .ge(1e-9)
          .rule("1 / (fps dt_min) <= 1e7 (steps a frame may take)"),
      Spec("shot.dt_max", T::Number)
          .to(&ShotSettings::dt_max)
          .def("1e-2")
          .unit("s")
          .gt(0)
          .rule(">= dt_min; with shot.integrator implicit the default is one frame (1 / fps)"),
      Spec("shot.gravity", T::Vec3)
          .to(&ShotSettings::gravity)
          .def("[0, -9.81, 0]")
          .unit("m/s^2")
          .ge(-1e4)
          .le(1e4),
      Spec("shot.domain", T::Map).required(),
      Spec("shot.domain.min", T::Vec3)
          .to(&ShotSettings::domain_min)
          .required()
          .unit("m")
          .rule(kInPositionRange),
      Spec("shot.domain.max", T::Vec3)
          .to(&ShotSettings::domain_max)
          .required()
          .unit("m")
          .rule(std::string("> min on every axis; ") + kInPositionRange),
      Spec("shot.dx", T::Number)
          .to(&ShotSettings::dx)
          .required()
          .unit("m")
          .ge(1e-6)
          .le(1e3)
          .rule("at most 2^20 cells per axis"),
      Spec("shot.threads", T::Int).to(&ShotSettings::threads).def("0").ge(0),
      Spec("shot.transfer", T::Enum).to(&ShotSettings::transfer).def("apic"),
      Spec("shot.quality", T::Enum)
          .to(&ShotSettings::quality)
          .optional("none: every value as written")
          .rule("see docs/accuracy.md#quality-presets"),
      Spec("shot.shell_velocities", T::Enum).to(&ShotSettings::shell_velocities).def("per_shell"),
      Spec("shot.fold_fields", T::Bool).to(&ShotSettings::fold_fields).def("true"),
      Spec("shot.contact_at", T::Enum).to(&ShotSettings::contact_at).def("surface"),
      Spec("shot.shell_guard", T::Bool).to(&ShotSettings::shell_guard).def("true"),
      Spec("shot.shell_guard_gap", T::Number)
          .to(&ShotSettings::shell_guard_gap)
          .def("0")
          .unit("m")
          .ge(0)
          .le(1e3)
          .rule("0: the thinnest contact layer less a fifth of it or 0.05 dx (contact_at surface), "
                "else the "
                "larger of 0.05 "
                "dx and the thickest"),
      Spec("shot.integrator", T::Enum)
          .to(&ShotSettings::integrator)
          .def("explicit")
          .rule("see docs/implicit.md"),
      Spec("shot.implicit_tolerance", T::Number)
          .to(&ShotSettings::implicit_tolerance)
          .def("1e-4")
          .unit("m/s")
          .gt(0)
          .le(1e3),
      Spec("shot.newton_max_iterations", T::Int)
          .to(&ShotSettings::newton_max_iterations)
          .def("30")
          .ge(1)
          .le(10000),
      Spec("shot.cg_max_iterations", T::Int)
          .to(&ShotSettings::cg_max_iterations)
          .def("500")
          .ge(1)
          .le(1000000),
      Spec("shot.implicit_preconditioner", T::Enum)
          .to(&ShotSettings::implicit_preconditioner)
          .def("factorised"),
      Spec("shot.implicit_theta", T::Number)
          .to(&ShotSettings::implicit_theta)
          .def("1")
          .ge(0.5)
          .le(1),
      Spec("shot.units", T::String).to(&ShotSettings::units).def("m").nonempty(),
      Spec("shot.on_integrity_failure", T::Enum)
          .to(&ShotSettings::on_integrity_failure)
          .def("warn"),
      // materials
      Spec("materials[].name", T::String)
          .to(&MaterialDesc::name)
          .required()
          .nonempty()
          .rule("unique"),
      Spec("materials[].type", T::Enum).to(&MaterialDesc::kind).required(),
      Spec("materials[].model", T::Enum)
          .to(&MaterialDesc::model)
          .def("fixed_corotated")
          .only_for({"elastic"}),
      Spec("materials[].youngs_modulus", T::Number)
          .to(&MaterialDesc::youngs_modulus)
          .def("1e5")
          .unit("Pa")
          .ge(1)
          .le(1e12),
      Spec("materials[].poisson_ratio", T::Number)
          .to(&MaterialDesc::poisson_ratio)
          .def("0.3")
          .ge(0)
          .lt(0.5)
          .rule(kStiffestModulus),
      Spec("materials[].density", T::Number)
          .to(&MaterialDesc::density)
          .def("1000")
          .unit("kg/m^3")
          .ge(0.1)
          .le(1e5),
      Spec("materials[].friction_angle", T::Number)
          .to(&MaterialDesc::friction_angle_deg)
          .def("30")
          .unit("deg")
          .ge(0)
          .lt(90)
          .only_for({"sand"}),
      Spec("materials[].cohesion", T::Number)
          .to(&MaterialDesc::cohesion)
          .def("0")
          .ge(0)
          .le(1)
          .only_for({"sand"}),
      Spec("materials[].critical_compression", T::Number)
          .to(&MaterialDesc::critical_compression)
          .def("0.025")
          .gt(0)
          .lt(1)
          .only_for({"snow"}),
      Spec("materials[].critical_stretch", T::Number)
          .to(&MaterialDesc::critical_stretch)
          .def("0.0075")
          .gt(0)
          .le(1)
          .only_for({"snow"}),
      Spec("materials[].hardening", T::Number)
          .to(&MaterialDesc::hardening)
          .def("10")
          .ge(0)
          .le(100)
          .only_for({"snow"}),
      Spec("materials[].color", T::Vec3)
          .to(&MaterialDesc::color)
          .optional("by type: elastic green, sand tan, snow white")
          .color(),
      // sources
      Spec("sources[].name", T::String)
          .optional("`source<i>` (i = list index)")
          .nonempty()
          .rule("unique"),
      Spec("sources[].material", T::String).required().rule("a name in materials"),
      Spec("sources[].shape", T::Shape)
          .required()
          .rule("not a plane; inside shot.domain, one cell in"),
      Spec("sources[].particles_per_cell", T::Number)
          .to(&SourceDesc::particles_per_cell)
          .def("8")
          .ge(1)
          .le(64),
      Spec("sources[].velocity", T::Vec3)
          .to(&SourceDesc::velocity)
          .def("[0, 0, 0]")
          .unit("m/s")
          .ge(-1e5)
          .le(1e5),
      Spec("sources[].seed", T::Int).to(&SourceDesc::seed).def("1").ge(0).le(4294967295.0),
      Spec("sources[].emit", T::Map)
          .optional("none: fill once at the start")
          .rule("velocity must be nonzero"),
      Spec("sources[].emit.frames", T::FrameRange)
          .to(&SourceDesc::emit_start, &SourceDesc::emit_end)
          .required()
          .ge(1)
          .le(999999999),
      // colliders
      Spec("colliders[].name", T::String)
          .optional("`collider<i>` (i = list index)")
          .nonempty()
          .rule("unique"),
      Spec("colliders[].shape", T::Shape)
          .required()
          .rule("its bounds (a plane: its point) within 2^17 dx of the origin"),
      Spec("colliders[].boundary", T::Enum).to(&ColliderDesc::boundary).def("separate"),
      Spec("colliders[].friction", T::Number).to(&ColliderDesc::friction).def("0").ge(0).le(10),
      Spec("colliders[].keyframes", T::List).def("[]").rule("times strictly increase"),
  });
  add(keyframe_specs("colliders[].keyframes[]"));
  add({
      // shell materials
      Spec("shell_materials[].name", T::String)
          .to(&ShellMaterialDesc::name)
          .required()
          .nonempty()
          .rule("unique"),
      Spec("shell_materials[].youngs_modulus", T::Number)
          .to(&ShellMaterialDesc::youngs_modulus)
          .def("1e6")
          .unit("Pa")
          .ge(1)
          .le(1e12),
      Spec("shell_materials[].poisson_ratio", T::Number)
          .to(&ShellMaterialDesc::poisson_ratio)
          .def("0.3")
          .ge(0)
          .lt(0.5),
      Spec("shell_materials[].density", T::Number)
          .to(&ShellMaterialDesc::density)
          .def("1000")
          .unit("kg/m^3")
          .ge(0.1)
          .le(1e5),
      Spec("shell_materials[].thickness", T::Number)
          .to(&ShellMaterialDesc::thickness)
          .def("0.001")
          .unit("m")
          .ge(1e-7)
          .le(1)
          .rule("< the radius of a sphere or cylinder shell"),
      Spec("shell_materials[].yield_stress", T::Number)
          .to(&ShellMaterialDesc::yield_stress)
          .def("0")
          .unit("Pa")
          .ge(0)
          .le(1e12),
      Spec("shell_materials[].stretch_limit", T::Number)
          .to(&ShellMaterialDesc::stretch_limit)
          .def("1.5")
          .gt(1)
          .le(1.9),
      Spec("shell_materials[].damping", T::Number)
          .to(&ShellMaterialDesc::damping)
          .def("0")
          .unit("1/s")
          .ge(0)
          .le(1e4),
      Spec("shell_materials[].stiffness_damping", T::Number)
          .to(&ShellMaterialDesc::stiffness_damping)
          .def("0")
          .unit("s")
          .ge(0)
          .le(1),
      Spec("shell_materials[].quadrature_inplane", T::Int)
          .to(&ShellMaterialDesc::quadrature_inplane)
          .def("3")
          .rule("one of: 1, 3, 6, 7"),
      Spec("shell_materials[].quadrature_thickness", T::Int)
          .to(&ShellMaterialDesc::quadrature_thickness)
          .def("3")
          .ge(1)
          .le(5),
      Spec("shell_materials[].friction", T::Number)
          .to(&ShellMaterialDesc::friction)
          .def("0.3")
          .ge(0)
          .le(10),
      Spec("shell_materials[].contact_stiffness", T::Number)
          .to(&ShellMaterialDesc::contact_stiffness)
          .optional("`youngs_modulus`")
          .unit("Pa")
          .gt(0)
          .le(1e12),
      Spec("shell_materials[].contact_shear", T::Number)
          .to(&ShellMaterialDesc::contact_shear)
          .optional("`contact_stiffness`")
          .unit("Pa")
          .gt(0)
          .le(1e12),
      Spec("shell_materials[].contact_thickness", T::Number)
          .to(&ShellMaterialDesc::contact_thickness)
          .optional("`thickness`")
          .unit("m")
          .gt(0)
          .le(1e3),
      Spec("shell_materials[].contact_samples", T::Int)
          .to(&ShellMaterialDesc::contact_samples)
          .def("1")
          .rule("one of: 1, 3, 6, 7"),
      Spec("shell_materials[].front_color", T::Vec3)
          .to(&ShellMaterialDesc::front_color)
          .optional("`render.shell_front`")
          .color(),
      Spec("shell_materials[].back_color", T::Vec3)
          .to(&ShellMaterialDesc::back_color)
          .optional("`render.shell_back`")
          .color(),
      // shells
      Spec("shells[].name", T::String)
          .optional("`shell<i>` (i = list index)")
          .nonempty()
          .rule("unique; letters, digits, `_`, `-` only"),
      Spec("shells[].material", T::String).required().rule("a name in shell_materials"),
      Spec("shells[].geometry", T::Map).required(),
      Spec("shells[].scale", T::Number).to(&ShellDesc::scale).def("1").ge(1e-6).le(1e6),
      Spec("shells[].rotate", T::Vec3).to(&ShellDesc::rotate_deg).def("[0, 0, 0]").unit("deg"),
      Spec("shells[].translate", T::Vec3)
          .to(&ShellDesc::translate)
          .def("[0, 0, 0]")
          .unit("m")
          .rule("the rest mesh inside shot.domain (one cell in with contact)"),
      Spec("shells[].velocity", T::Vec3)
          .to(&ShellDesc::velocity)
          .def("[0, 0, 0]")
          .unit("m/s")
          .ge(-1e5)
          .le(1e5),
      Spec("shells[].pressure", T::Number)
          .to(&ShellDesc::pressure)
          .def("0")
          .unit("Pa")
          .ge(-1e12)
          .le(1e12),
      Spec("shells[].point_loads", T::List).def("[]"),
      Spec("shells[].point_loads[].index", T::Int)
          .to(&PointLoadDesc::index)
          .required()
          .ge(0)
          .rule("< number of vertices"),
      Spec("shells[].point_loads[].force", T::Vec3)
          .to(&PointLoadDesc::force)
          .required()
          .unit("N")
          .ge(-1e12)
          .le(1e12),
      Spec("shells[].pins", T::List).def("[]"),
      Spec("shells[].pins[].indices", T::IntList)
          .optional(kPinSelector)
          .ge(0)
          .rule("non-empty; each < number of vertices"),
      Spec("shells[].pins[].box", T::Map).optional(kPinSelector),
      Spec("shells[].pins[].box.min", T::Vec3).to(&PinDesc::box_min).required().unit("m"),
      Spec("shells[].pins[].box.max", T::Vec3)
          .to(&PinDesc::box_max)
          .required()
          .unit("m")
          .rule(">= min on every axis"),
      Spec("shells[].pins[].group", T::String)
          .optional(kPinSelector)
          .nonempty()
          .rule("geometry type mesh only"),
      Spec("shells[].pins[].components", T::Bool3)
          .to(&PinDesc::components)
          .def("[true, true, true]")
          .rule("at least one true"),
      Spec("shells[].pins[].keyframes", T::List).def("[]").rule("times strictly increase"),
      Spec("shells[].pins[].release", T::Number)
          .to(&PinDesc::release_time)
          .optional("never")
          .unit("s")
          .ge(0),
  });
  add(keyframe_specs("shells[].pins[].keyframes[]"));
  add({
      Spec("shells[].output_refine", T::Int).to(&ShellDesc::output_refine).def("0").ge(0).le(4),
      Spec("shells[].write_mesh", T::Bool).to(&ShellDesc::write_mesh).def("true"),
      Spec("shells[].contact", T::Enum).to(&ShellDesc::contact).def("auto"),
      // shell geometry (the value of shells[].geometry)
      Spec("shells[].geometry.type", T::Enum).to(&ShellDesc::kind).required(),
      Spec("shells[].geometry.size", T::Vec2)
          .to(&ShellDesc::size)
          .def("[1, 1]")
          .unit("m")
          .gt(0)
          .only_for({"sheet"}),
      Spec("shells[].geometry.resolution", T::Int2)
          .to(&ShellDesc::resolution)
          .def("[10, 10]")
          .ge(1)
          .le(2000)
          .only_for({"sheet", "cylinder"})
          .rule("closed cylinder: first >= 3"),
      Spec("shells[].geometry.radius", T::Number)
          .to(&ShellDesc::radius)
          .def("0.5")
          .unit("m")
          .gt(0)
          .only_for({"cylinder", "sphere"}),
      Spec("shells[].geometry.height", T::Number)
          .to(&ShellDesc::height)
          .def("1")
          .unit("m")
          .gt(0)
          .only_for({"cylinder"}),
      Spec("shells[].geometry.angle", T::Number)
          .to(&ShellDesc::angle_deg)
          .def("360")
          .unit("deg")
          .gt(0)
          .le(360)
          .only_for({"cylinder"}),
      Spec("shells[].geometry.subdivisions", T::Int)
          .to(&ShellDesc::subdivisions)
          .def("2")
          .ge(0)
          .le(7)
          .only_for({"sphere"}),
      Spec("shells[].geometry.path", T::String)
          .required()
          .nonempty()
          .only_for({"mesh"})
          .rule("readable file; relative to the scene file"),
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
  });
  return schema;
}

}  // namespace shellmpm::scenefile

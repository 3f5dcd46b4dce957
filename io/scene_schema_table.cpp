// The scene format, one row per key: io/scene_schema.h says what a row holds, and
// docs/scene-format.md shows this table (a test keeps the two equal).
#include <string>
#include <vector>

#include "io/scene_schema_parts.h"
#include "io/scene_spec.h"
#include "sim/scene/scene.h"

namespace shellmpm::scenefile {
namespace {

using T = KeyType;

}  // namespace

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

std::vector<KeySpec> build_schema() {
  std::vector<KeySpec> schema;
  auto add = [&schema](std::vector<KeySpec> specs) {
    schema.insert(schema.end(), specs.begin(), specs.end());
  };
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
          .rule(
              ">= dt_min; with an implicit step (also auto's) the default is one frame (1 / fps)"),
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
      Spec("shot.plasticity_in_solve", T::Bool).to(&ShotSettings::plasticity_in_solve).def("false"),
      Spec("shot.shell_fields_in_solve", T::Bool)
          .to(&ShotSettings::shell_fields_in_solve)
          .def("false"),
      Spec("shot.friction_in_solve", T::Bool).to(&ShotSettings::friction_in_solve).def("false"),
      Spec("shot.friction_stick_speed", T::Number)
          .to(&ShotSettings::friction_stick_speed)
          .def("1e-3")
          .unit("m/s")
          .gt(0)
          .le(1),
      Spec("shot.units", T::String).to(&ShotSettings::units).def("m").nonempty(),
      Spec("shot.on_integrity_failure", T::Enum)
          .to(&ShotSettings::on_integrity_failure)
          .def("warn"),
      Spec("shot.on_energy_gain", T::Enum).to(&ShotSettings::on_energy_gain).def("warn"),
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
  add(shell_keys());
  add(output_keys());
  return schema;
}

}  // namespace shellmpm::scenefile

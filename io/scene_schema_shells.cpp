// The scene format's table, shell part: shell materials, shells and their geometry
// (io/scene_schema_parts.h).
#include <string>
#include <vector>

#include "io/scene_schema_parts.h"
#include "io/scene_spec.h"
#include "sim/scene/scene.h"

namespace shellmpm::scenefile {

std::vector<KeySpec> shell_keys() {
  using T = KeyType;
  std::vector<KeySpec> schema;
  auto add = [&schema](std::vector<KeySpec> specs) {
    schema.insert(schema.end(), specs.begin(), specs.end());
  };
  const std::string kPinSelector = "give exactly one of indices, box, group";
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
  });
  return schema;
}

}  // namespace shellmpm::scenefile

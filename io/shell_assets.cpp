#include "io/shell_assets.h"

#include <sstream>

#include "io/mesh_reader.h"
#include "io/scene_reader.h"
#include "io/shell_mesh_reader.h"
#include "io/user_error.h"
#include "sim/shell/mesh_check.h"
#include "sim/shell/shell_object.h"

namespace shellmpm {

void load_shell_meshes(Scene& scene) {
  for (std::size_t i = 0; i < scene.shells.size(); ++i) {
    ShellDesc& sd = scene.shells[i];
    const std::string key = "shells[" + std::to_string(i) + "]";
    const std::string where = sd.kind == ShellDesc::Kind::Mesh && !sd.mesh_where.empty()
                                  ? sd.mesh_where
                                  : scene.path + ": " + key + ".geometry";
    if (sd.kind == ShellDesc::Kind::Mesh && !sd.mesh)
      sd.mesh = std::make_shared<ShellMesh>(read_shell_mesh(sd.mesh_path, where));
    const ShellMesh rest = build_shell_rest_mesh(sd);
    // Procedural meshes are valid by construction (tests/sim/shell/test_shell_object.cpp); the
    // check is for mesh files, and would take seconds at the largest resolutions.
    const auto problems = sd.kind == ShellDesc::Kind::Mesh
                              ? check_shell_mesh(rest.vertices, rest.triangles)
                              : std::vector<MeshProblem>{};
    if (!problems.empty()) {
      std::ostringstream os;
      os << "the control mesh cannot be simulated (" << problems.size() << " problem"
         << (problems.size() > 1 ? "s" : "") << "):";
      for (std::size_t p = 0; p < problems.size() && p < 8; ++p)
        os << "\n  " << problems[p].message;
      if (problems.size() > 8) os << "\n  ...";
      throw UserError(where, 0, "", os.str());
    }
    check_shell_indices(sd, static_cast<int>(rest.vertices.size()), scene.path);
    for (const PinDesc& pin : sd.pins) {
      const std::string at = pin.where.empty() ? where : pin.where;
      if (!pin.group.empty() && !rest.groups.count(pin.group)) {
        std::string known;
        for (const auto& g : rest.groups) known += (known.empty() ? "" : ", ") + g.first;
        throw detail::user_error_at(
            at, "no vertex group '" + pin.group + "' in " + sd.mesh_path +
                    " (groups: " + (known.empty() ? std::string("none") : known) + ")");
      }
      if (pin.has_box) {
        bool any = false;
        for (const Vec3d& p : rest.vertices)
          any = any || ((p.array() >= pin.box_min.array()).all() &&
                        (p.array() <= pin.box_max.array()).all());
        if (!any)
          throw detail::user_error_at(
              at, "the pin box selects no control point of shell '" + sd.name +
                      "' (boxes select by rest position after scale, rotate and translate)");
      }
    }
  }
}

}  // namespace shellmpm

#include "sim/solver/integrator_choice.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/mpm/constitutive.h"
#include "sim/shell/shell_object.h"
#include "sim/solver/number_format.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {
namespace {

std::string g3(double v) {
  return format_number("%.3g", v);
}

/// A count of steps, whole.
std::string whole(double v) {
  return format_number("%.0f", v);
}

}  // namespace

double shell_contact_stable_dt(const ShellMaterialDesc& m, double cfl, double dx) {
  const double kc = m.contact_stiffness.value_or(m.youngs_modulus);
  const double gamma = m.contact_shear.value_or(kc);
  return cfl * dx / std::sqrt(2.0 * std::max(kc, gamma) / m.density);
}

IntegratorChoice choose_integrator(const Scene& scene) {
  const ShotSettings& s = scene.shot;
  IntegratorChoice c;
  c.explicit_dt = std::numeric_limits<double>::infinity();
  std::string what;  // the object that sets dt_e
  auto take = [&](double dt, const std::string& name) {
    if (dt < c.explicit_dt) {
      c.explicit_dt = dt;
      what = name;
    }
  };
  for (std::size_t i = 0; i < scene.shells.size(); ++i) {
    const ShellDesc& d = scene.shells[i];
    const ShellMaterialDesc& m = scene.shell_materials[static_cast<std::size_t>(d.material)];
    if (d.kind != ShellDesc::Kind::Mesh || d.mesh) {
      take(shell_stable_dt(m, shortest_edge(build_shell_rest_mesh(d)), s.cfl),
           "shell '" + d.name + "' (its stiffness over its shortest edge)");
    }
    if (shell_has_contact(scene, i))
      take(shell_contact_stable_dt(m, s.cfl, s.dx),
           "shell '" + d.name + "' (its contact stiffness)");
  }
  for (const SourceDesc& src : scene.sources) {
    const MaterialDesc& m = scene.materials[static_cast<std::size_t>(src.material)];
    const double modulus =
        ConstitutiveModelT<double>::from_desc(m).wave_modulus(Mat3d::Identity(), 1.0);
    if (modulus > 0)
      take(s.cfl * s.dx / std::sqrt(modulus / m.density), "material '" + m.name + "'");
  }
  const double frame = 1.0 / s.fps;
  const std::string dte = "the explicit step " + g3(c.explicit_dt) + " s, set by " + what;
  if (c.explicit_dt < s.dt_min) {
    c.integrator = Integrator::Implicit;
    c.reason = dte + ", is below shot.dt_min = " + g3(s.dt_min) + " s";
  } else if (!grid_needed(scene) && !scene.shells.empty() &&
             frame / c.explicit_dt > kAutoStepsPerFrame) {
    c.integrator = Integrator::Implicit;
    c.reason = dte + ", takes " + whole(frame / c.explicit_dt) +
               " steps a frame (shells without contact: over " + whole(kAutoStepsPerFrame) + ")";
  } else {
    c.integrator = Integrator::Explicit;
    c.reason = std::isfinite(c.explicit_dt)
                   ? dte + ", takes " + whole(frame / c.explicit_dt) + " steps a frame" +
                         (grid_needed(scene) ? " (on the grid: explicit unless below dt_min)"
                                             : " (at most " + whole(kAutoStepsPerFrame) + ")")
                   : "nothing stiff bounds the explicit step";
  }
  return c;
}

void resolve_integrator(Scene& scene) {
  ShotSettings& s = scene.shot;
  if (s.integrator != Integrator::Auto) return;
  const IntegratorChoice c = choose_integrator(scene);
  s.integrator = c.integrator;
  s.integrator_reason = c.reason;
  if (c.integrator == Integrator::Implicit && !s.dt_max_set) s.dt_max = 1.0 / s.fps;
}

}  // namespace shellmpm

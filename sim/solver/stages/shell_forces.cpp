#include "sim/solver/stages/shell_forces.h"

#include "sim/core/parallel.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool ShellForcesStage::needed(const Scene& s) {
  // Implicit: the shells take their forces inside implicit_shells (without contact) and
  // implicit_grid (in contact).
  return s.shot.integrator == Integrator::Explicit && !s.shells.empty();
}

void ShellForcesStage::run(StepContext& c) {
  const Vec3d zero = Vec3d::Zero();
  c.shell_loads.resize(c.shells.size());
  for (std::size_t i = 0; i < c.shells.size(); ++i) {
    ShellObject& sh = *c.shells[i];
    c.shell_loads[i] = sh.load_forces();
    if (!c.contacts[i]) {
      sh.forces(c.scene.shot.gravity, c.shell_forces[i], c.opt.serial);
      continue;
    }
    // On the grid, gravity is applied to the nodes.
    sh.forces(zero, c.shell_forces[i], c.opt.serial);
    const Real damp = static_cast<Real>(sh.material().damping);
    if (damp > 0)
      parallel_for(
          sh.size(), 16384,
          [&](std::size_t b, std::size_t e) {
            for (std::size_t j = b; j < e; ++j) c.shell_forces[i][j] -= damp * sh.mass[j] * sh.v[j];
          },
          c.opt.serial);
  }
}

}  // namespace shellmpm

#include "sim/solver/stages/contact_grid.h"

#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool ContactGridStage::needed(const Scene& s) {
  // Implicit: the contact particles' normal forces are part of the grid solve.
  return any_contact_shell(s) && s.shot.integrator == Integrator::Explicit;
}

void ContactGridStage::run(StepContext& c) {
  contact_normal_forces(c.grid, c.shell_table, c.grid_shells, static_cast<Real>(c.dt),
                        c.opt.serial);
  if (c.colliders.empty()) c.apply_walls();  // else after the colliders (colliders.cpp)
}

}  // namespace shellmpm

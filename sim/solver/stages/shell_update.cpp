#include "sim/solver/stages/shell_update.h"

#include "sim/solver/body_energies.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool ShellUpdateStage::needed(const Scene& s) {
  return s.shot.integrator == Integrator::Explicit && any_direct_shell(s);
}

void ShellUpdateStage::run(StepContext& c) {
  for (std::size_t i = 0; i < c.shells.size(); ++i) {
    if (c.contacts[i]) continue;
    ShellObject& sh = *c.shells[i];
    c.energy_supplied += sh.integrate(c.shell_forces[i], c.time, c.dt, c.opt.serial);
    c.energy_supplied += load_work(c.shell_loads[i], sh.v, c.dt);  // x moved by dt v
  }
}

}  // namespace shellmpm

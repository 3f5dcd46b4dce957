#include "sim/solver/stages/shell_update.h"

#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool ShellUpdateStage::needed(const Scene& s) {
  return s.shot.integrator == Integrator::Explicit && any_direct_shell(s);
}

void ShellUpdateStage::run(StepContext& c) {
  for (std::size_t i = 0; i < c.shells.size(); ++i)
    if (!c.contacts[i])
      c.energy_supplied += c.shells[i]->integrate(c.shell_forces[i], c.time, c.dt, c.opt.serial);
}

}  // namespace shellmpm

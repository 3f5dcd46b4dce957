#include "sim/solver/stages/contact_forces.h"

#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool ContactForcesStage::needed(const Scene& s) {
  return any_contact_shell(s);
}

void ContactForcesStage::run(StepContext& c) {
  std::size_t k = 0;
  for (std::size_t i = 0; i < c.shells.size(); ++i) {
    if (!c.contacts[i]) continue;
    GridShell& g = c.grid_shells[k++];
    c.energy_supplied += prescribe_pins(g, c.time, c.dt);
    if (c.scene.shot.integrator == Integrator::Implicit) {
      // The forces are part of the implicit grid solve: P2G transfers momentum only.
      g.contact->update_positions(g.shell->x.data(), c.opt.serial);
      g.force.assign(g.shell->size(), Vec3::Zero());
      continue;
    }
    // (forces also updates the site positions.)
    g.force.swap(c.shell_forces[i]);
    g.contact->forces(g.shell->x.data(), g.force.data(), c.opt.serial);
  }
  c.clamp_to_domain();
}

}  // namespace shellmpm

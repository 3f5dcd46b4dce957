#include "sim/solver/stages/g2p.h"

#include "sim/solver/body_energies.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool G2pStage::needed(const Scene& s) {
  return grid_needed(s);
}

void G2pStage::run(StepContext& c) {
  TransferParams tp = c.transfer_params();
  const Real dt = tp.dt;
  if (!c.grid_shells.empty())
    tp.others = [&c, dt](std::size_t b, GridNode* buf, PadBox*) {
      shell_g2p_block(c.grid, c.shell_table, c.grid_shells, dt, b, buf);
    };
  if (c.scene.shot.shell_guard) {
    c.shell_x_start.resize(c.grid_shells.size());
    for (std::size_t s = 0; s < c.grid_shells.size(); ++s)
      c.shell_x_start[s] = c.grid_shells[s].shell->x;
  }
  const bool fields = c.shell_fields.active();
  if (fields) {
    ShellFields::SkipFn skip;
    ShellFields::ColliderGate gate;
    const bool gated = c.shell_field_rule(skip, gate);
    c.shell_fields.before_g2p(c.grid, skip, c.opt.serial, gated ? &gate : nullptr);
    if (gated) c.energy_supplied += c.shell_fields.gate_work();
  }
  grid_to_particles(c.particles, c.grid, tp);
  if (fields) c.shell_fields.after_g2p(c.grid_shells, dt, c.opt.serial);
  for (const GridShell& g : c.grid_shells) c.energy_supplied += pin_transfer_work(g);
  // Explicit loads: the control points moved by dt v in g2p and after_g2p.
  for (std::size_t i = 0, k = 0; i < c.shells.size() && i < c.shell_loads.size(); ++i)
    if (c.contacts[i])
      c.energy_supplied += load_work(c.shell_loads[i], c.grid_shells[k++].shell->v, c.dt);
  c.clamp_to_domain();
}

}  // namespace shellmpm

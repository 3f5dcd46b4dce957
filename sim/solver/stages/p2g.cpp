#include "sim/solver/stages/p2g.h"

#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool P2gStage::needed(const Scene& s) {
  return grid_needed(s);
}

void P2gStage::run(StepContext& c) {
  TransferParams tp = c.transfer_params();
  const Real dt = tp.dt;
  // A lone folding shell's heights are summed with its control points' P2G.
  FoldHeights* heights = c.shell_fields.active()
                             ? c.shell_fields.begin_p2g(c.grid, c.grid_shells, c.opt.serial)
                             : nullptr;
  if (!c.grid_shells.empty())
    tp.others = [&c, dt, heights](std::size_t b, GridNode* buf, PadBox* box) {
      shell_p2g_block(c.grid, c.shell_table, c.grid_shells, dt, b, buf, heights, box);
    };
  particles_to_grid(c.particles, c.grid, tp);
  if (c.shell_fields.active())
    c.shell_fields.p2g(c.grid, c.grid_shells, dt, &c.particles, tp.first_bulk, c.opt.serial);
}

}  // namespace shellmpm

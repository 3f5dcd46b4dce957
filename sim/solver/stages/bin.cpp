#include "sim/solver/stages/bin.h"

#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool BinStage::needed(const Scene& s) {
  return grid_needed(s);
}

void BinStage::run(StepContext& c) {
  const bool shells = !c.grid_shells.empty();
  if (shells) c.shell_table.positions(c.grid_shells, c.shell_points, c.opt.serial);
  c.grid.bin(shells ? &c.shell_points : nullptr, c.particles.x, c.opt.serial);
}

}  // namespace shellmpm

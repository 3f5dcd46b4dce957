#include "sim/solver/stages/grid_update.h"

#include "sim/core/parallel.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool GridUpdateStage::needed(const Scene& s) {
  return grid_needed(s);
}

void GridUpdateStage::run(StepContext& c) {
  const Vec3 g = c.scene.shot.gravity.cast<Real>();
  const Real dt = static_cast<Real>(c.dt);
  const bool walls = c.grid_shells.empty();
  parallel_for_each(
      c.grid.num_grid_blocks(), 16,
      [&](std::size_t b) {
        c.grid.for_each_massive_node(b, [&](GridNode& nd, const Vec3i& n) {
          const Real inv_m = Real(1) / nd.m;
          for (int a = 0; a < 3; ++a) {
            Real v = nd.v[a] * inv_m + dt * g[a];
            if (walls && n[a] < kWallCells && v < 0) v = 0;
            if (walls && n[a] > c.domain_cells[a] - kWallCells && v > 0) v = 0;
            nd.v[a] = v;
          }
        });
      },
      c.opt.serial);
}

}  // namespace shellmpm

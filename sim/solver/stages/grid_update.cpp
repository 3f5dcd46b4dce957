#include "sim/solver/stages/grid_update.h"

#include <cmath>

#include "sim/core/parallel.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool GridUpdateStage::needed(const Scene& s) {
  return grid_needed(s) && s.shot.integrator == Integrator::Explicit;
}

void GridUpdateStage::run(StepContext& c) {
  const Vec3 g = c.scene.shot.gravity.cast<Real>();
  const Real dt = static_cast<Real>(c.dt);
  // The domain walls act here unless a later stage applies them: the contact grid (shells
  // in contact) or the colliders, which must see the velocity before the walls clamp it.
  const bool walls = c.grid_shells.empty() && c.colliders.empty();
  parallel_for_each(
      c.grid.num_grid_blocks(), 16,
      [&](std::size_t b) {
        c.grid.for_each_massive_node(b, [&](GridNode& nd, const Vec3i& n) {
          // v = p / m. A node that only the far tips of its points' stencils reach
          // along all three axes (points within round-off below a half-cell position,
          // w = (1.5 - fx)^2 / 2 per axis, about 1e-13 each in float) gets a subnormal
          // mass, whose reciprocal overflows to inf (1 / m > max for m < 1 / max),
          // while p / m is an ordinary velocity: divide there. Normal masses keep the
          // reciprocal (same results as before).
          const bool normal = std::isnormal(nd.m);
          const Real inv_m = normal ? Real(1) / nd.m : Real(0);
          for (int a = 0; a < 3; ++a) {
            Real v = (normal ? nd.v[a] * inv_m : nd.v[a] / nd.m) + dt * g[a];
            if (walls && n[a] < kWallCells && v < 0) v = 0;
            if (walls && n[a] > c.domain_cells[a] - kWallCells && v > 0) v = 0;
            nd.v[a] = v;
          }
        });
      },
      c.opt.serial);
}

}  // namespace shellmpm

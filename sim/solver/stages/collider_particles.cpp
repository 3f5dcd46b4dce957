#include "sim/solver/stages/collider_particles.h"

#include "sim/collider/particle_projection.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool ColliderParticlesStage::needed(const Scene& s) {
  return grid_needed(s) && !s.colliders.empty();
}

void ColliderParticlesStage::run(StepContext& c) {
  const double dx = c.grid.dx();
  project_out_of_colliders(c.colliders, dx, c.dt, c.particles.x, c.particles.v, nullptr,
                           c.opt.serial);
  for (GridShell& g : c.grid_shells)
    project_out_of_colliders(c.colliders, dx, c.dt, g.shell->x, g.shell->v, &g.held, c.opt.serial);
  // A collider can push a point past the domain's last cell: back inside, as after g2p.
  c.clamp_to_domain();
}

}  // namespace shellmpm

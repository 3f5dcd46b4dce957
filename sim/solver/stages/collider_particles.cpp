#include "sim/solver/stages/collider_particles.h"

#include "sim/collider/particle_projection.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool ColliderParticlesStage::needed(const Scene& s) {
  return !s.colliders.empty() && (grid_needed(s) || any_direct_shell(s));
}

void ColliderParticlesStage::run(StepContext& c) {
  const bool grid = grid_needed(c.scene);
  // Without a grid no collider stage has posed the colliders for this step.
  if (!grid)
    for (Collider& col : c.colliders) col.begin_step(c.time, c.dt);
  const double dx = c.scene.shot.dx;
  std::vector<std::uint8_t> held;
  std::vector<Vec3d> target;
  for (std::size_t i = 0; i < c.shells.size(); ++i) {
    if (c.contacts[i]) continue;
    c.shells[i]->pin_targets(c.time, c.dt, held, target);  // released pins hold nothing
    project_out_of_colliders(c.colliders, dx, c.dt, c.shells[i]->x, c.shells[i]->v, &held,
                             c.opt.serial, c.contact_offset(*c.shells[i]));
  }
  if (!grid) return;
  project_out_of_colliders(c.colliders, dx, c.dt, c.particles.x, c.particles.v, nullptr,
                           c.opt.serial);
  for (GridShell& g : c.grid_shells)
    project_out_of_colliders(c.colliders, dx, c.dt, g.shell->x, g.shell->v, &g.held, c.opt.serial,
                             c.contact_offset(*g.shell));
  // A collider can push a point past the domain's last cell: back inside, as after g2p.
  c.clamp_to_domain();
}

}  // namespace shellmpm

#include "sim/solver/stages/collider_particles.h"

#include "sim/collider/particle_projection.h"
#include "sim/solver/body_energies.h"
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
  // What the projections supply (energy_audit.h): the points' impulses times moving
  // colliders' velocities and their potential energy, and for a shell a moving collider
  // moved, the change of what it stores (two energy evaluations, only then).
  ProjectionWork work;
  work.gravity = c.scene.shot.gravity;
  const auto project_shell = [&](std::size_t i, const std::vector<std::uint8_t>* pinned) {
    ShellObject& sh = *c.shells[i];
    work.mass = [&sh](std::size_t j) { return static_cast<double>(sh.mass[j]); };
    x_before_ = sh.x;
    const ProjectionStats st = project_out_of_colliders(c.colliders, dx, c.dt, sh.x, sh.v, pinned,
                                                        c.opt.serial, c.contact_offset(sh), &work);
    c.energy_supplied += st.work;
    if (st.moving == 0) return;  // a static collider does no work
    const double after = shell_stored_energy(c, i);
    std::swap(sh.x, x_before_);
    const double before = shell_stored_energy(c, i);
    std::swap(sh.x, x_before_);
    c.energy_supplied += after - before;
  };
  for (std::size_t i = 0; i < c.shells.size(); ++i) {
    if (c.contacts[i]) continue;
    c.shells[i]->pin_targets(c.time, c.dt, held, target);  // released pins hold nothing
    project_shell(i, &held);
  }
  if (!grid) return;
  const ParticleSet& p = c.particles;
  work.mass = [&](std::size_t q) {
    return static_cast<double>(p.volume_of(q)) * c.densities[p.material_of(q)];
  };
  c.energy_supplied += project_out_of_colliders(c.colliders, dx, c.dt, c.particles.x, c.particles.v,
                                                nullptr, c.opt.serial, 0, &work)
                           .work;
  for (GridShell& g : c.grid_shells)
    for (std::size_t i = 0; i < c.shells.size(); ++i)
      if (c.shells[i].get() == g.shell) project_shell(i, &g.held);
  // A collider can push a point past the domain's last cell: back inside, as after g2p.
  c.clamp_to_domain();
}

}  // namespace shellmpm

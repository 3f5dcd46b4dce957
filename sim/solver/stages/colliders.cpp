#include "sim/solver/stages/colliders.h"

#include "sim/core/parallel.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool CollidersStage::needed(const Scene& s) {
  return grid_needed(s) && !s.colliders.empty();
}

void CollidersStage::run(StepContext& c) {
  for (Collider& col : c.colliders) col.begin_step(c.time, c.dt);
  // The implicit grid stage has marked the reach for the step it took (c.dt) already.
  if (c.scene.shot.integrator != Integrator::Implicit) c.compute_collider_reach();
  // Contact at the surfaces: the shared nodes' velocities before the conditions, for the
  // bodies there that are not near a collider (ShellFields::ColliderGate, g2p).
  if (c.shell_fields.contact_at_surfaces())
    c.shell_fields.keep_free_velocities(c.grid, c.opt.serial);
  // With the shells' fields in the implicit solve, the solve's constraints, its friction
  // and the control points' penalty are the colliders' conditions for the step: applied
  // again to the solved velocities they moved the nodes the solve left free (a plate
  // pressing a steel can put 3-7 J a step into its membrane that no force paid for,
  // docs/implicit.md). Particles still leave the colliders by collider_particles. (Slots
  // exist only after an implicit step with the fields in the solve.)
  if (c.shell_fields.has_slots()) return;
  const double dx = c.grid.dx();
  // The work of the moving colliders (energy_audit.h): per block, summed in block order.
  work_.assign(c.grid.num_grid_blocks(), 0.0);
  parallel_for_each(
      c.grid.num_grid_blocks(), 16,
      [&](std::size_t b) {
        const Vec3i corner = unpack_block(c.grid.gblock_key[b]) * kBlockSize;
        Aabb box;
        box.lo = c.grid.node_position(corner).array() - dx;
        box.hi = c.grid.node_position(corner + Vec3i::Constant(kBlockSize - 1)).array() + dx;
        for (std::size_t k = 0; k < c.colliders.size(); ++k) {
          const Collider& col = c.colliders[k];
          if (!col.bounds().overlaps(box)) continue;
          c.grid.for_each_massive_node(b, [&](GridNode& nd, const Vec3i& n) {
            const Vec3i l = n - corner;
            if (!c.collider_reach.engaged(b, block_node(l[0], l[1], l[2]), k)) return;
            Vec3 v(nd.v[0], nd.v[1], nd.v[2]);
            const Vec3d x = c.grid.node_position(n);
            if (col.apply(x, v)) {
              if (col.animated()) {
                const Vec3d dv(v[0] - nd.v[0], v[1] - nd.v[1], v[2] - nd.v[2]);
                work_[b] += static_cast<double>(nd.m) * dv.dot(col.velocity(x));
              }
              nd.v[0] = v[0];
              nd.v[1] = v[1];
              nd.v[2] = v[2];
            }
          });
        }
      },
      c.opt.serial);
  for (const double w : work_) c.energy_supplied += w;
  // The domain walls after the colliders: a ground within kWallCells of the domain's edge
  // must see the node's velocity into it, or the wall (frictionless) would zero it first
  // and the ground's Coulomb friction, which scales with that velocity, would never act
  // (a sand pile crept over a rough ground at dx 0.02, its floor 2.5 cells above the
  // domain's edge, as over ice).
  c.apply_walls();
}

}  // namespace shellmpm

#include "sim/solver/stages/g2p.h"

#include <algorithm>
#include <limits>

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
  if (fields && c.shell_fields.contact_at_surfaces() && !c.colliders.empty()) {
    // Contact at the surfaces: a collider's condition reaches the bodies near it only.
    ShellFields::ColliderGate gate;
    gate.engaged = [&c](std::size_t g, int n) {
      for (std::size_t k = 0; k < c.colliders.size(); ++k)
        if (c.collider_reach.engaged(g, n, k)) {
          Vec3 v = Vec3::Zero();
          const Vec3i l(n >> 4, (n >> 2) & 3, n & 3);
          const Vec3i node = unpack_block(c.grid.gblock_key[g]) * kBlockSize + l;
          if (c.colliders[k].apply(c.grid.node_position(node), v)) return true;
        }
      return false;
    };
    gate.phi = [&c](const Vec3d& x) {
      double phi = std::numeric_limits<double>::infinity();
      for (const Collider& col : c.colliders) phi = std::min(phi, col.phi(x));
      return phi;
    };
    gate.apply = [&c](std::size_t g, int n, Vec3& v) {
      const Vec3i l(n >> 4, (n >> 2) & 3, n & 3);
      const Vec3d x = c.grid.node_position(unpack_block(c.grid.gblock_key[g]) * kBlockSize + l);
      for (std::size_t k = 0; k < c.colliders.size(); ++k)
        if (c.collider_reach.engaged(g, n, k)) c.colliders[k].apply(x, v);
    };
    gate.reach = static_cast<Real>(kColliderReachCells * c.grid.dx());
    c.shell_fields.before_g2p(
        c.grid, [&c](const Vec3i& n) { return c.wall_node(n); }, c.opt.serial, &gate);
  } else if (fields) {
    c.shell_fields.before_g2p(
        c.grid, [&c](const Vec3i& n) { return c.single_velocity_node(n); }, c.opt.serial);
  }
  grid_to_particles(c.particles, c.grid, tp);
  if (fields) c.shell_fields.after_g2p(c.grid_shells, dt, c.opt.serial);
  c.clamp_to_domain();
}

}  // namespace shellmpm

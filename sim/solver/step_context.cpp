#include "sim/solver/step_context.h"

#include <algorithm>
#include <limits>

#include "sim/core/parallel.h"

namespace shellmpm {

TransferParams StepContext::transfer_params() const {
  TransferParams tp;
  tp.dt = static_cast<Real>(dt);
  tp.mls = scene.shot.transfer == Transfer::Mls;
  // Implicit: the stress enters the grid solve (implicit_grid), not P2G.
  tp.stress = scene.shot.integrator == Integrator::Explicit;
  tp.serial = opt.serial;
  tp.models = &models;
  tp.densities = &densities;
  tp.first_bulk = static_cast<std::uint32_t>(shell_table.size());
  return tp;
}

void StepContext::clamp_to_domain() {
  const ShotSettings& s = scene.shot;
  Vec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    lo[a] = static_cast<Real>(s.domain_min[a] + s.dx);
    hi[a] = static_cast<Real>(s.domain_min[a] + (domain_cells[a] - 1) * s.dx);
  }
  const auto clamp = [&](std::vector<Vec3>& xs) {
    parallel_for_each(
        xs.size(), kParticleGrain, [&](std::size_t p) { xs[p] = xs[p].cwiseMax(lo).cwiseMin(hi); },
        opt.serial);
  };
  clamp(particles.x);
  for (GridShell& g : grid_shells) {
    clamp(g.shell->x);
    clamp(g.contact->x);
  }
}

void StepContext::apply_walls() {
  parallel_for_each(
      grid.num_grid_blocks(), 16,
      [&](std::size_t b) {
        // Blocks whose nodes all lie clear of the walls are left alone.
        const Vec3i c = unpack_block(grid.gblock_key[b]) * kBlockSize;
        bool clear = true;
        for (int a = 0; a < 3; ++a)
          clear =
              clear && c[a] >= kWallCells && c[a] + kBlockSize - 1 <= domain_cells[a] - kWallCells;
        if (clear) return;
        grid.for_each_massive_node(b, [&](GridNode& nd, const Vec3i& n) {
          for (int a = 0; a < 3; ++a) {
            if (n[a] < kWallCells && nd.v[a] < 0) nd.v[a] = 0;
            if (n[a] > domain_cells[a] - kWallCells && nd.v[a] > 0) nd.v[a] = 0;
          }
        });
      },
      opt.serial);
}

double StepContext::contact_offset(const ShellObject& sh) const {
  if (scene.shot.contact_at != ContactAt::Surface) return 0;
  const ShellMaterialDesc& m = sh.material();
  return 0.5 * m.contact_thickness.value_or(m.thickness);
}

void StepContext::compute_collider_reach() {
  const bool shells = !grid_shells.empty();
  if (shells) {
    shell_table.velocities(grid_shells, reach_velocities);
    // Contact at the surfaces: each shell point reaches half its contact thickness further.
    if (scene.shot.contact_at == ContactAt::Surface &&
        shell_point_offsets.size() != shell_table.size()) {
      shell_point_offsets.resize(shell_table.size());
      for (std::uint32_t i = 0; i < shell_table.size(); ++i)
        shell_point_offsets[i] =
            static_cast<Real>(contact_offset(*grid_shells[shell_table.shell(i)].shell));
    }
  }
  collider_reach.compute(
      grid, shells ? &shell_points : nullptr, shells ? &reach_velocities : nullptr, particles.x,
      particles.v, colliders, kColliderReachCells * grid.dx(), dt, opt.serial,
      shells && scene.shot.contact_at == ContactAt::Surface ? &shell_point_offsets : nullptr);
}

bool StepContext::wall_node(const Vec3i& n) const {
  for (int a = 0; a < 3; ++a)
    if (n[a] < kWallCells || n[a] > domain_cells[a] - kWallCells) return true;
  return false;
}

bool StepContext::single_velocity_node(const Vec3i& n) const {
  if (wall_node(n)) return true;
  Aabb at;
  at.lo = at.hi = grid.node_position(n);
  for (const Collider& c : colliders) {
    if (!c.bounds().overlaps(at)) continue;
    Vec3 v = Vec3::Zero();
    if (c.apply(at.lo, v)) return true;
  }
  return false;
}

bool StepContext::shell_field_rule(ShellFields::SkipFn& skip, ShellFields::ColliderGate& gate) {
  if (!shell_fields.contact_at_surfaces() || colliders.empty()) {
    skip = [this](const Vec3i& n) { return single_velocity_node(n); };
    return false;
  }
  // Contact at the surfaces: a collider's condition reaches the bodies near it only.
  skip = [this](const Vec3i& n) { return wall_node(n); };
  const auto node_at = [this](std::size_t g, int n) -> Vec3i {
    return unpack_block(grid.gblock_key[g]) * kBlockSize + Vec3i(n >> 4, (n >> 2) & 3, n & 3);
  };
  gate.engaged = [this, node_at](std::size_t g, int n) {
    for (std::size_t k = 0; k < colliders.size(); ++k)
      if (collider_reach.engaged(g, n, k)) {
        Vec3 v = Vec3::Zero();
        if (colliders[k].apply(grid.node_position(node_at(g, n)), v)) return true;
      }
    return false;
  };
  gate.phi = [this](const Vec3d& x) {
    double phi = std::numeric_limits<double>::infinity();
    for (const Collider& col : colliders) phi = std::min(phi, col.phi(x));
    return phi;
  };
  gate.apply = [this, node_at](std::size_t g, int n, Vec3& v) {
    const Vec3d x = grid.node_position(node_at(g, n));
    for (std::size_t k = 0; k < colliders.size(); ++k)
      if (collider_reach.engaged(g, n, k)) colliders[k].apply(x, v);
  };
  // The moving colliders' velocity, for the energy audit (none when all are static).
  bool moving = false;
  for (const Collider& col : colliders) moving = moving || col.animated();
  if (moving)
    gate.velocity = [this, node_at](std::size_t g, int n) -> Vec3d {
      const Vec3d x = grid.node_position(node_at(g, n));
      for (std::size_t k = 0; k < colliders.size(); ++k) {
        if (!collider_reach.engaged(g, n, k)) continue;
        if (colliders[k].phi(x) > 0) continue;
        return colliders[k].animated() ? colliders[k].velocity(x) : Vec3d::Zero();
      }
      return Vec3d::Zero();
    };
  gate.reach = static_cast<Real>(kColliderReachCells * grid.dx());
  return true;
}

void StepContext::add_particles_from(std::size_t i, const std::vector<Vec3d>& pts) {
  const SourceDesc& src = scene.sources[i];
  const auto mat = static_cast<std::uint16_t>(src.material);
  const Real vol = static_cast<Real>(samplers[i].particle_volume());
  const Vec3 vel = src.velocity.cast<Real>();
  const Real pl0 = models[mat].initial_plastic();
  particles.reserve_more(pts.size(), false);
  for (const Vec3d& p : pts) particles.push_back(p.cast<Real>(), vel, vol, mat, pl0);
}

void StepContext::add_dissipation(const ShellObject* sh, double w) {
  for (std::size_t i = 0; i < shells.size() && i < shell_dissipated.size(); ++i)
    if (shells[i].get() == sh) shell_dissipated[i] += w;
}

}  // namespace shellmpm

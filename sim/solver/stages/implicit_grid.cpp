#include "sim/solver/stages/implicit_grid.h"

#include <algorithm>
#include <sstream>

#include "sim/core/simulation_error.h"
#include "sim/implicit/grid_step.h"
#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {
namespace {
/// Solves again a step at most this often with the groups its solution joined.
constexpr int kMaxRegroups = 3;
/// And at most this often with the walls holding what its solution drove into them (the
/// held set grows each time: a block pressed onto the floor's band took four).
constexpr int kMaxWallSolves = 6;

/// Whether the walls after the step (StepContext::apply_walls) would change a solved
/// velocity by more than tol [m/s]: motion the solve never saw, which strains a stiff
/// shell whose stencils reach into the walls (a can on a bed of sand one cell deep).
bool drives_into_walls(const StepContext& c, double tol) {
  const SparseGrid& grid = c.grid;
  for (std::size_t b = 0; b < grid.num_grid_blocks(); ++b) {
    const Vec3i corner = unpack_block(grid.gblock_key[b]) * kBlockSize;
    bool clear = true;
    for (int a = 0; a < 3; ++a)
      clear = clear && corner[a] >= kWallCells &&
              corner[a] + kBlockSize - 1 <= c.domain_cells[a] - kWallCells;
    if (clear) continue;
    for (int n = 0; n < kBlockNodes; ++n) {
      const GridNode& nd = grid.gblock_nodes[b][std::size_t(n)];
      if (!(nd.m > 0)) continue;
      const Vec3i p = corner + Vec3i(n >> 4, (n >> 2) & 3, n & 3);
      for (int a = 0; a < 3; ++a)
        if ((p[a] < kWallCells && nd.v[a] < -tol) ||
            (p[a] > c.domain_cells[a] - kWallCells && nd.v[a] > tol))
          return true;
    }
  }
  return false;
}
}  // namespace

bool ImplicitGridStage::needed(const Scene& s) {
  return s.shot.integrator == Integrator::Implicit && grid_needed(s);
}

void ImplicitGridStage::run(StepContext& c) {
  if (models_.empty())
    for (const MaterialDesc& m : c.scene.materials)
      models_.push_back(ConstitutiveModelT<double>::from_desc(m));
  const ShotSettings& shot = c.scene.shot;
  GridStepInput in;
  in.particles = &c.particles;
  in.grid = &c.grid;
  in.models = &models_;
  in.densities = &c.densities;
  in.colliders = &c.colliders;
  in.gravity = shot.gravity;
  in.domain_cells = c.domain_cells;
  in.wall_cells = kWallCells;
  in.mls = shot.transfer == Transfer::Mls;
  in.serial = c.opt.serial;
  in.first_bulk = static_cast<std::uint32_t>(c.shell_table.size());
  in.factorise = shot.implicit_preconditioner == ImplicitPreconditioner::Factorised;
  in.friction_in_solve = shot.friction_in_solve;
  in.friction_stick_speed = shot.friction_stick_speed;
  if (kls_.size() != c.grid_shells.size()) {
    kls_.resize(c.grid_shells.size());
    for (std::size_t s = 0; s < kls_.size(); ++s)
      kls_[s].kl = c.grid_shells[s].shell->double_kl(&kls_[s].coupling);
  }
  for (std::size_t s = 0; s < kls_.size(); ++s) {
    c.grid_shells[s].shell->sync_double_kl(*kls_[s].kl);
    kls_[s].kl->set_plasticity_in_energy(shot.plasticity_in_solve);
  }
  const NewtonOptions opt = newton_options(shot);
  if (cap_epoch_ != c.advance_epoch) {
    cap_ = 0;
    cap_epoch_ = c.advance_epoch;
  }
  double dt = cap_ > 0 ? std::min(c.dt, cap_) : c.dt;
  bool retried = false;
  int iterations = 0;
  FieldSlots slots;
  std::vector<Vec3> slot_vel;
  std::vector<std::array<GridNode, kBlockNodes>> before;  // the grid as P2G left it
  std::vector<std::array<GridNode, kBlockNodes>> solved;  // the last solve's velocities
  int regroups = 0, walled = 0;
  std::vector<double> friction_bounds;  // friction in the solve: the last solve's bounds
  in.friction_bounds = &friction_bounds;
  const auto pose_slots = [&]() {
    ShellFields::SkipFn skip;
    ShellFields::ColliderGate gate;
    const bool gated = c.shell_field_rule(skip, gate);
    c.shell_fields.slots(c.grid, c.grid_shells, skip, gated ? &gate : nullptr, slots, c.opt.serial);
  };
  while (true) {
    for (Collider& col : c.colliders) col.begin_step(c.time, dt);
    if (!c.colliders.empty()) {
      c.dt = dt;  // the reach's prediction covers the step tried
      c.compute_collider_reach();
      in.reach = &c.collider_reach;
    }
    if (shot.shell_fields_in_solve && c.shell_fields.active() && !c.shell_fields.has_slots()) {
      // The shells' own fields as unknowns of the solve (field_slots.h), their groups from
      // the rule p2g applied; the walls and the colliders posed for the first step tried.
      pose_slots();
      in.slots = &slots;
      in.slot_out = &slot_vel;
    }
    std::unique_ptr<GridShellTerms> shells;
    if (!c.grid_shells.empty()) {
      shells = std::make_unique<GridShellTerms>(c.grid, c.shell_table, c.grid_shells, kls_, c.time,
                                                dt, c.opt.serial);
      shells->set_colliders(&c.colliders);
      in.shells = shells.get();
    }
    if (regroups == 0 && walled == 0) before = c.grid.gblock_nodes;
    double work = 0;
    in.collider_work = &work;
    const NewtonReport rep = implicit_grid_step(in, dt, opt);
    c.implicit_frame.add(rep.iterations, rep.cg_iterations, rep.residual);
    iterations = rep.iterations;
    if (rep.converged && in.slots && regroups < kMaxRegroups &&
        c.shell_fields.regroup(c.grid, before, slot_vel)) {
      // Bodies the step drove together: solved again with them in one group.
      ++regroups;
      solved.swap(c.grid.gblock_nodes);
      c.grid.gblock_nodes = before;
      in.start = &solved;
      pose_slots();
      continue;
    }
    if (rep.converged && walled < kMaxWallSolves && drives_into_walls(c, shot.implicit_tolerance)) {
      // Solved again with the walls holding what the solution drove into them.
      ++walled;
      solved.swap(c.grid.gblock_nodes);
      c.grid.gblock_nodes = before;
      in.start = &solved;
      if (in.slots) pose_slots();
      continue;
    }
    if (rep.converged) {
      c.energy_supplied += work;
      break;
    }
    in.start = nullptr;  // a shorter step starts afresh
    friction_bounds.clear();
    retried = true;
    ++c.implicit_frame.retries;
    dt *= 0.5;
    if (dt < shot.dt_min) {
      std::ostringstream os;
      os << "at t = " << c.time
         << " s the implicit grid step did not converge even at dt = " << 2 * dt << " s (residual "
         << rep.residual << " m/s after " << rep.iterations << " Newton iterations"
         << (rep.line_search_failed ? ", the line search found no decrease" : "")
         << "; shot.implicit_tolerance = " << shot.implicit_tolerance
         << " m/s); raise shot.newton_max_iterations or shot.implicit_tolerance, or lower "
            "shot.dt_min";
      throw SimulationError(os.str());
    }
  }
  if (in.slots) c.shell_fields.take_solution(c.grid, slots, slot_vel);
  if (retried)
    cap_ = dt;
  else if (cap_ > 0 && 3 * iterations <= opt.max_iterations)
    cap_ = std::max(2 * cap_, 2 * dt);  // grows from the cap, not from a short step
  c.dt = dt;
  // Pinned control points: their velocity over the step actually taken.
  for (GridShell& g : c.grid_shells) c.energy_supplied += prescribe_pins(g, c.time, dt);
  c.apply_walls();
}

}  // namespace shellmpm

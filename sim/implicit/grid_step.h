// Backward Euler on the MPM grid for bulk materials (Gast, Schroeder, Stomakhin, Jiang and
// Teran 2015). After a P2G of mass and momentum only (no stress), one step of dt minimises
// over the velocities v_i of the massive grid nodes
//   E(v) = sum_i m_i |v_i - v_i^n|^2 / 2 - dt sum_i m_i g . v_i + sum_p V_p psi(F_p(v)),
//   F_p(v) = (I + dt sum_i v_i (grad w_ip)^T) F_p^n,
// the elastic energy at the positions the nodes would move to (the supplement's forces as
// functions of x* = x + dt v, "ignoring further plastic flow"). grad w_ip is the kernel
// gradient (APIC) or MLS's 4 w_ip (x_i - x_p) / dx^2, the same velocity gradient G2P applies
// to F afterwards. Plasticity (sand, snow) is applied after the step by its stage, as in
// the explicit path.
//
// Constraints, projected inside CG (newton.h): nodes without mass; the domain walls
// (a component whose predicted velocity v^n + dt g points into a wall within kWallCells is
// held at 0, and, in a step solved again, one the last solution drove into it); colliders, at the
// nodes within reach of material (collider_reach.h), from the predicted velocity: sticky nodes take
// the collider's velocity, slip and separate (approaching) nodes keep the collider's normal
// velocity and move freely along the surface. Coulomb friction follows the solve at those nodes,
// with the normal impulse the constraint applied (the explicit collider stage takes it from the
// approach speed, which the constraint has already stopped here), or is a term of the
// objective (friction_in_solve).
//
// Shells in contact add their Kirchhoff-Love and contact energies at the moved control
// points (grid_shells.h); the preconditioner then includes their tangent on the nodes they
// reach.
//
// Everything is double: the constitutive models in ConstitutiveModelT<double>, the node
// velocities, the sums. Per-node sums are gathered from per-particle-block buffers in the
// grid's fixed order (sim/mpm/sparse_grid.h), so a solve is the same for any thread count.
// Jacobi preconditioner: m_i + dt^2 sum_p V_p c_p |grad w_ip|^2, c_p the particle's wave
// modulus (sim/mpm/constitutive.h).
#pragma once
#include <vector>

#include "sim/collider/collider.h"
#include "sim/collider/collider_reach.h"
#include "sim/implicit/grid_shells.h"
#include "sim/implicit/newton.h"
#include "sim/mpm/constitutive.h"
#include "sim/mpm/particles.h"
#include "sim/mpm/sparse_grid.h"

namespace shellmpm {

struct GridStepInput {
  const ParticleSet* particles = nullptr;  ///< binned into `grid` (bulk only)
  SparseGrid* grid = nullptr;              ///< after a P2G without stress: mass, momentum
  const std::vector<ConstitutiveModelT<double>>* models = nullptr;
  const std::vector<Real>* densities = nullptr;
  const std::vector<Collider>* colliders = nullptr;  ///< posed for the step (begin_step)
  /// The nodes within reach of each collider (collider_reach.h), for the same pose; null:
  /// every node inside a collider takes its condition.
  const ColliderReach* reach = nullptr;
  Vec3d gravity{0, 0, 0};
  Vec3i domain_cells{0, 0, 0};
  int wall_cells = 3;
  bool mls = false;
  bool serial = false;
  /// Shells in contact, their points binned in front of the bulk particles (bulk particle
  /// q as first_bulk + q); null: none.
  GridShellTerms* shells = nullptr;
  std::uint32_t first_bulk = 0;
  /// The shells' own velocities at shared nodes (field_slots.h; null: none): their groups'
  /// masses and velocities replace the nodes' where the bulk field's group has them, and
  /// each slot adds three unknowns after the nodes'. On convergence slot_out gets the
  /// slots' velocities.
  const FieldSlots* slots = nullptr;
  std::vector<Vec3>* slot_out = nullptr;
  /// A solution of the same step to start Newton from (null: v^n + dt g): the nodes'
  /// velocities (in v), and the slots' from slots->slot_start; projected onto the
  /// constraints. The step solved again after its groups were joined (field_slots.h), or
  /// after its solution drove nodes into a wall the prediction left free, starts where the
  /// last solve ended; the walls then also hold what that solution drove into them.
  const std::vector<std::array<GridNode, kBlockNodes>>* start = nullptr;
  /// With shells: `factorised` factorises the tangent on the nodes the shells reach
  /// (Jacobi elsewhere); `block_jacobi` keeps its diagonal.
  bool factorise = true;
  /// Coulomb friction at the slip and separate collider nodes inside the solve (the
  /// lagged potential of friction_potential.h; the step is solved again with the normal
  /// impulses its first solution needed), or after it (false: the velocities change by
  /// the friction impulse after the solve).
  bool friction_in_solve = false;
  /// With friction in the solve: LaggedFriction::eps [m/s] (shot.friction_stick_speed).
  double friction_stick_speed = 1e-3;
  /// With friction in the solve (null: none): each node's Coulomb bound to start from
  /// (empty: none; the step is solved without friction first), and on return those its
  /// solution needs. A step solved again after its groups were joined starts from the
  /// last solve's and is solved once more only where they moved by over a quarter.
  std::vector<double>* friction_bounds = nullptr;
  /// On convergence (non-null): the moving colliders' work over the step [J]
  /// (energy_audit.h).
  double* collider_work = nullptr;
};

/// The objective of one grid step (for tests) and its start (v^n + dt g, constraints applied).
std::unique_ptr<ImplicitObjective> grid_objective(const GridStepInput& in, double dt, VecXd& u0);

/// One step: on convergence writes the node velocities into the grid (v, in place of the
/// momentum) and returns; otherwise leaves the grid's mass and momentum as they were.
NewtonReport implicit_grid_step(const GridStepInput& in, double dt, const NewtonOptions& opt);

}  // namespace shellmpm

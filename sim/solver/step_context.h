// What the stages of a step share (sim/solver/stages/). The solver owns one StepContext,
// fills it at setup and hands it to every stage in order; each field says which stages
// write it and which read it, so a new stage can see what it may use and what it must
// leave as it found it.
#pragma once
#include <limits>
#include <memory>
#include <vector>

#include "sim/collider/collider.h"
#include "sim/collider/collider_reach.h"
#include "sim/contact/shell_contact.h"
#include "sim/contact/shell_fields.h"
#include "sim/contact/shell_guard.h"
#include "sim/contact/shell_transfer.h"
#include "sim/mpm/constitutive.h"
#include "sim/mpm/particles.h"
#include "sim/mpm/sparse_grid.h"
#include "sim/mpm/transfer.h"
#include "sim/scene/scene.h"
#include "sim/shell/shell_object.h"
#include "sim/solver/frame_stats.h"
#include "sim/solver/source_sampler.h"

namespace shellmpm {

struct SolverOptions {
  bool serial = false;       ///< no threads (tests compare against parallel runs)
  bool fill_sources = true;  ///< sample fill sources at construction (off when resuming)
};

struct StepContext {
  // Fixed at setup; every stage reads them.
  Scene scene;
  SolverOptions opt;
  std::vector<ConstitutiveModel> models;  ///< per bulk material
  std::vector<Real> densities;            ///< per bulk material [kg/m^3]
  Vec3i domain_cells{0, 0, 0};            ///< cells of the domain along each axis
  double shell_dt = std::numeric_limits<double>::infinity();  ///< shells' stable step [s]

  // Time. The solver writes them before each step; stages read them.
  double time = 0;  ///< at the start of the step [s]
  double dt = 0;    ///< of this step [s]
  /// Counts the solver's advances (Solver::advance_to): state a stage keeps between steps
  /// only within one advance (a cache) is the same on a re-run and on a resume.
  std::uint64_t advance_epoch = 0;

  // Sources and colliders. emit writes the samplers' emission state; colliders poses
  // each collider for the step (read by collider_particles and the walls check).
  std::vector<SourceSampler> samplers;
  std::vector<Collider> colliders;

  // Bulk particles. p2g reads; g2p writes x, v, C, F; plasticity writes F and plastic;
  // emit appends.
  ParticleSet particles;
  /// Counts the reorderings of `particles` (the solver's per-frame sort; stages that keep
  /// particle indices across steps compare it).
  std::uint64_t particle_epoch = 0;
  // The combined grid. bin writes the binning; p2g writes mass and momentum; grid turns
  // momentum into velocity; contact_grid, colliders and g2p (shared nodes) change
  // velocities; g2p reads.
  SparseGrid grid;

  // Shells, in scene order. shell_forces writes shell_forces; shell_update integrates
  // the shells without contact; contact moves each contact shell's forces into its
  // GridShell (a swap) and adds the contact forces; g2p moves the contact shells'
  // control points; denting writes the shells' plastic state.
  std::vector<std::unique_ptr<ShellObject>> shells;
  std::vector<std::vector<Vec3>> shell_forces;  ///< per shell [N]
  /// Per shell, the explicit step's pressure and point loads at its start (empty without
  /// loads; shell_forces writes it): their work is the force times the control points'
  /// displacement over the step (shell_update, g2p).
  std::vector<std::vector<Vec3d>> shell_loads;
  std::vector<std::unique_ptr<ShellContact>> contacts;  ///< per shell; null: no contact
  std::vector<GridShell>
      grid_shells;                 ///< the shells with contact, their control points on the grid
  ShellFields shell_fields;        ///< per-shell velocities on shared nodes: p2g, g2p
  ShellPointTable shell_table;     ///< grid shells' points in the combined binning
  std::vector<Vec3> shell_points;  ///< written by bin, read by p2g and g2p
  /// Which nodes take each collider's condition (collider_reach.h): written by colliders
  /// and implicit_grid, for the colliders' pose at the end of the step.
  ColliderReach collider_reach;
  std::vector<Vec3> reach_velocities;  ///< scratch of compute_collider_reach
  /// Per shell point of shell_table: contact_offset of its shell (compute_collider_reach).
  std::vector<Real> shell_point_offsets;
  /// The grid shells' control points at the start of the step (x^n): written by g2p
  /// before it moves them, read by shell_guard, which runs after the colliders have
  /// projected points out (so x - dt v is not x^n for every point any more).
  std::vector<std::vector<Vec3>> shell_x_start;

  // Accumulated results (checkpointed): friction writes contact_step and friction_work,
  // denting writes plastic_work.
  ContactStepStats contact_step;  ///< the last step's return mapping
  /// shell_guard's counts over the frame so far (the solver zeroes it at a frame's start):
  /// pairs and sweeps are maxima over the steps, impulses, zoned and unresolved sums.
  ShellGuardStats guard_frame;
  /// The implicit stages' counts over the frame so far (zeroed at a frame's start).
  ImplicitStats implicit_frame;
  double friction_work = 0;  ///< [J]
  double plastic_work = 0;   ///< [J]
  // The frame's energy ledger (sim/integrity/energy_audit.h; the solver zeroes it at a
  // frame's start): colliders, implicit_grid, collider_particles and emit add what they
  // supply; denting and friction add each shell's dissipation.
  double energy_supplied = 0;            ///< [J]
  std::vector<double> shell_dissipated;  ///< per shell, in scene order [J]
  /// Adds w to the frame's dissipation of shell sh (one of `shells`).
  void add_dissipation(const ShellObject* sh, double w);

  /// Transfer settings for this step (dt, APIC or MLS, materials, where bulk starts).
  TransferParams transfer_params() const;
  /// Keeps particles, control points and contact particles one cell inside the domain.
  void clamp_to_domain();
  /// Marks the nodes within reach of the colliders (posed for the step) in collider_reach.
  void compute_collider_reach();
  /// How far out from a shell's surface its contact surface lies [m]: half its contact
  /// thickness with shot.contact_at: surface, else 0 (colliders meet the surface itself).
  double contact_offset(const ShellObject& sh) const;
  /// Stops the velocity components that point into the domain walls.
  void apply_walls();
  /// Nodes where shells keep one shared velocity: walls and colliders.
  bool single_velocity_node(const Vec3i& n) const;
  /// Nodes within kWallCells of the domain's boundary.
  bool wall_node(const Vec3i& n) const;
  /// How the shells' fields meet the walls and colliders at shared nodes: with contact at
  /// the surfaces and colliders, a gate (ShellFields::ColliderGate) and the walls as the
  /// nodes that keep one velocity; else no gate and walls and colliders both keep one.
  /// Returns whether `gate` was set.
  bool shell_field_rule(ShellFields::SkipFn& skip, ShellFields::ColliderGate& gate);
  /// Appends bulk particles of source i at positions pts (at rest velocity of the source).
  void add_particles_from(std::size_t source, const std::vector<Vec3d>& pts);
};

/// Nodes this close to the domain boundary act as walls.
constexpr int kWallCells = 3;
/// Particles per parallel chunk in the particle loops.
constexpr std::size_t kParticleGrain = 4096;

}  // namespace shellmpm

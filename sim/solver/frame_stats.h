// What one frame of simulation reports (written to the statistics file by io/).
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "sim/core/types.h"
#include "sim/integrity/energy_audit.h"
#include "sim/integrity/integrity_report.h"

namespace shellmpm {

/// What the implicit integrator did over a frame (shot.integrator implicit).
struct ImplicitStats {
  int steps = 0;              ///< implicit steps taken (the frame's substeps)
  int solves = 0;             ///< Newton solves (one per shell per attempt)
  int newton_iterations = 0;  ///< summed over the solves
  int max_newton_iterations = 0;
  int cg_iterations = 0;    ///< summed over the solves
  double max_residual = 0;  ///< largest final residual of a solve [m/s]
  int retries = 0;          ///< steps taken again at half the step (a solve did not converge)
  void add(int newton, int cg, double residual) {
    ++solves;
    newton_iterations += newton;
    max_newton_iterations = newton > max_newton_iterations ? newton : max_newton_iterations;
    cg_iterations += cg;
    max_residual = residual > max_residual ? residual : max_residual;
  }
};

struct FrameStats {
  int frame = 0;
  double time = 0;  ///< simulation time at the end of the frame [s]
  int substeps = 0;
  double dt_min = 0, dt_max = 0;  ///< range of steps taken [s]
  std::size_t particles = 0;
  double kinetic_energy = 0;  ///< sum 1/2 m v^2 [J]
  double elastic_energy = 0;  ///< sum V0 psi(F) [J]
  Vec3d momentum{0, 0, 0};    ///< sum m v [kg m/s]
  double mass = 0;            ///< total particle mass [kg]
  double max_speed = 0;       ///< [m/s]
  std::size_t grid_blocks = 0;
  // Shells (all shells summed).
  std::size_t shell_points = 0;      ///< control points
  double shell_kinetic_energy = 0;   ///< [J]
  double shell_membrane_energy = 0;  ///< [J]
  double shell_bending_energy = 0;   ///< [J]
  double shell_plastic_work = 0;     ///< dissipated by denting since the start [J]
  double shell_max_strain = 0;       ///< largest principal Hencky strain
  Vec3d shell_momentum{0, 0, 0};     ///< sum m v over control points [kg m/s]
  // Contact (shells on the grid).
  std::size_t contact_particles = 0;   ///< contact particles of all shells
  std::size_t contact_compressed = 0;  ///< in contact (s3 < 1) after the frame's last step
  std::size_t contact_sliding = 0;     ///< sliding in the frame's last step
  std::size_t contact_nodes = 0;       ///< grid nodes where bodies met in the frame's last step
  double contact_energy = 0;           ///< sum V psi [J]
  double friction_work = 0;            ///< dissipated by sliding friction since the start [J]
  // The shell guard (sim/contact/shell_guard.h) over the frame's steps.
  std::size_t guard_pairs = 0;       ///< most proximity pairs in one step
  std::size_t guard_impulses = 0;    ///< pair impulses applied, summed over the steps
  std::size_t guard_zoned = 0;       ///< points moved in impact zones, summed
  std::size_t guard_unresolved = 0;  ///< pairs left closing at a step's end, summed
  bool implicit = false;             ///< shot.integrator implicit: `implicit_stats` is filled
  ImplicitStats implicit_stats;
  /// What the integrity monitor found (crossings, collider penetration, non-finite, and
  /// energy nothing supplied).
  IntegrityReport integrity;
  /// Each bulk material's and shell's energies at the frame's end, and the frame's
  /// energy balance (sim/integrity/energy_audit.h).
  std::vector<BodyEnergy> bodies;
  EnergyAudit energy;
  /// Wall-clock seconds per stage, in stage order (not deterministic, unlike the rest).
  std::vector<std::pair<std::string, double>> stage_seconds;
  double wall_seconds = 0;
};

}  // namespace shellmpm

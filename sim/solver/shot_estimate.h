// How long a shot will take, before it runs (`shellmpm check`): the stable step now (the
// step limits at the current wave speeds, plus what the sources will emit), the substeps a
// frame takes, and the seconds a frame costs on the stages the scene switches on, each at
// its throughput per thread measured by the benchmarks (bench/mpm_throughput,
// bench/contact_throughput; the figures are in README's speed section).
#pragma once
#include <vector>

#include "sim/solver/step_limits.h"

namespace shellmpm {

class Solver;

// The throughputs below were measured on the 2-core development machine (AMD EPYC,
// AVX-512 dispatch) on 2026-12-05 (the shells' in its last session); an SSE-only
// machine runs the bulk about 1.3x, the Kirchhoff-Love forces about 2.1x and the contact
// points about 1.2x slower.
/// Seconds one thread spends on one bulk particle for one step (P2G, grid, G2P, stress):
/// bench/mpm_throughput, APIC, float, 5.5M particle-steps/s per thread.
constexpr double kBulkParticleStepSeconds = 1.0 / 5.5e6;
/// Seconds one thread spends on one layer evaluation of the Kirchhoff-Love forces (one
/// in-plane quadrature point of one triangle at one point through the thickness):
/// bench/shell_throughput, 60M layer evaluations/s per thread.
constexpr double kShellLayerSeconds = 1.0 / 60e6;
/// Seconds one thread spends on one control point or contact particle of a shell in
/// contact for one step (its P2G and G2P, the contact forces, friction, the fields):
/// bench/contact_throughput, the 75 ms of a 106 ms step not spent in the Kirchhoff-Love
/// forces, over its 298k control points and contact particles.
constexpr double kContactPointStepSeconds = 0.075 / 298e3;

/// What `estimate_shot` finds.
struct ShotEstimate {
  std::vector<StepLimit> limits;  ///< smallest first (step_limits with upcoming particles)
  double dt = 0;                  ///< the stable step now [s]
  double substeps_per_frame = 0;  ///< ceil(1 / (fps dt))
  /// How much smaller than `dt` the step of compressed snow can get (>= 1; 1 without snow).
  double snow_step_shrink = 1;
  int threads = 1;
  // Seconds per frame on `threads` threads, by what costs them.
  double bulk_seconds = 0;     ///< bulk particles (at the peak count)
  double shell_seconds = 0;    ///< Kirchhoff-Love forces of every shell
  double contact_seconds = 0;  ///< control points and contact particles on the grid
  double seconds_per_frame() const { return bulk_seconds + shell_seconds + contact_seconds; }
};

/// The estimate for `solver` as built (before its first step).
/// @param peak_bulk_particles the most bulk particles the shot will hold (fill + emitted)
/// @param threads             the worker threads the run will use (>= 1)
ShotEstimate estimate_shot(const Solver& solver, double peak_bulk_particles, int threads);

}  // namespace shellmpm

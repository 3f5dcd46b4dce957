// What sets the explicit time step: every bound that Solver::stable_dt takes the minimum
// of, one entry per object (a shell's shortest edge, a shell's contact stiffness, a bulk
// material's wave speed, the fastest particles, shells and colliders, shot.dt_max), with
// the step it imposes and a sentence naming the object and the value. `check` prints the
// list and warns when the step would fall below shot.dt_min; the run's dt_min error names
// the first entry. The numbers are those of the solver (tests/sim/solver/test_step_limits.cpp
// asserts that the smallest equals Solver::stable_dt()).
#pragma once
#include <string>
#include <vector>

namespace shellmpm {

class Solver;

enum class StepLimitKind {
  DtMax,          ///< shot.dt_max
  ShellElastic,   ///< membrane and bending stiffness over a shell's shortest rest edge
  ShellContact,   ///< a shell's contact stiffness k_c or shear gamma over its density
  Material,       ///< longitudinal wave speed of a bulk material (its particles' state)
  ParticleSpeed,  ///< the fastest bulk particle of a material
  ShellSpeed,     ///< the fastest control point of a shell on the grid (contact on)
  ColliderSpeed,  ///< a collider's largest point speed at the current time
  SourceSpeed,    ///< upcoming only: the speed of particles a source is still to emit
};

/// The name of a kind, e.g. "shell elastic", "material wave speed".
const char* to_string(StepLimitKind kind);

/// One bound on the step.
struct StepLimit {
  StepLimitKind kind = StepLimitKind::DtMax;
  /// The largest step this cause allows [s]; NaN when a velocity is not finite (diverged).
  double dt = 0;
  /// Names the object and the value, e.g. "shell 'film': membrane/bending stiffness over
  /// its shortest control-mesh edge, 0.17 mm between vertices 12 and 13 at (0.1, 0, 0.2)".
  std::string detail;
  /// What raises this bound (a coarser mesh, a softer material, a larger dx, ...).
  std::string hint;
  /// True for bounds from particles that an emitting source has not made yet (at rest,
  /// at the source's velocity); Solver::stable_dt() does not see them until they exist.
  bool upcoming = false;
};

/// The bounds on the step of `solver` in its current state, sorted by dt, smallest first
/// (NaN entries first). Without `upcoming`, the minimum of the list's dt equals
/// solver.stable_dt(); with it, the sources still to emit are added (speed and material
/// wave speed at rest), as `check` needs before anything is emitted.
std::vector<StepLimit> step_limits(const Solver& solver, bool upcoming = false);

/// One sentence for a step that is too small: the first limit (its detail and dt) and
/// every other limit whose dt is below dt_min, each with its hint; e.g. "limited by
/// material 'steel': ... (1.0e-07 s); to raise it: a softer material ...". `limits` is
/// sorted as step_limits returns it and not empty. When a stiffness (a shell's, its
/// contact's or a material's) sets the step, it ends by naming the implicit integrator.
std::string describe_step_limits(const std::vector<StepLimit>& limits, double dt_min);

}  // namespace shellmpm

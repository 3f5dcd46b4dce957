// shot.integrator: auto. One integrator for the whole shot (every stage of a step is
// explicit or implicit), chosen from the scene at t = 0 by the explicit step's stiffness
// bound, dt_e: the smallest over each shell's membrane and bending waves on its shortest
// control-mesh edge, each contact shell's contact stiffness, and each bulk material's
// wave speed at rest (the bounds Solver::stable_dt takes before motion):
//   1. dt_e < shot.dt_min: implicit (an explicit run would stop at t = 0);
//   2. no grid (shells without contact only) and dt_e below a frame / kAutoStepsPerFrame:
//      implicit (stiff sheets without contact: the implicit step follows the motion and
//      was 22x to 590x cheaper per frame, docs/implicit.md);
//   3. else explicit (soft shells, bulk material, shells in contact: explicit was faster
//      where both can run, docs/implicit.md).
// `check` prints the choice and its reason; an implicit choice without shot.dt_max given
// sets it to one frame, as `integrator: implicit` does.
#pragma once
#include <string>

#include "sim/scene/scene.h"

namespace shellmpm {

/// Rule 2's threshold: explicit steps per frame above which auto steps shells without
/// contact implicitly (aluminium_dent's 30,000 do, cloth_swing's 412 do not).
constexpr double kAutoStepsPerFrame = 2000;

struct IntegratorChoice {
  Integrator integrator = Integrator::Explicit;  ///< Explicit or Implicit
  double explicit_dt = 0;  ///< the explicit step's stiffness bound dt_e [s]; inf if none
  std::string reason;      ///< one sentence: the rule that chose, with its numbers
};

/// The explicit step's bound from a contact shell's contact stiffness k_c and shear gamma
/// (psi'' <= 2 max(k_c, gamma) at s3 = 0) over its density [s].
double shell_contact_stable_dt(const ShellMaterialDesc& m, double cfl, double dx);

/// The choice for `scene` (its shells' meshes loaded), whatever shot.integrator says.
IntegratorChoice choose_integrator(const Scene& scene);

/// When shot.integrator is auto: sets it to the choice, shot.integrator_reason to the
/// reason and, for implicit without shot.dt_max given, dt_max to one frame. Otherwise
/// leaves the scene as it is.
void resolve_integrator(Scene& scene);

}  // namespace shellmpm

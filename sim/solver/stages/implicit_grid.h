// Stage "implicit_grid": with shot.integrator implicit, the grid's velocities come from a
// backward Euler solve (sim/implicit/grid_step.h) instead of grid_update's explicit
// momentum / mass + dt g (P2G then transfers no stress). A solve that does not converge is
// taken again at half the step, down to shot.dt_min; the step it took is left in
// StepContext::dt for the stages after it (colliders, G2P, plasticity) and the solver.
// The step adapts: after a retry the steps that follow start at the step that converged
// and double after each one that converges in at most a third of
// shot.newton_max_iterations, so a hard stretch (an impact) does not pay for a failed
// solve at every step. The cap lives within one advance (a frame), as a resume needs.
// Shells in contact are part of the solve (sim/implicit/grid_shells.h): their
// Kirchhoff-Love and contact energies at the control points the grid moves.
#pragma once
#include <cstdint>
#include <vector>

#include "sim/implicit/grid_shells.h"
#include "sim/mpm/constitutive.h"
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class ImplicitGridStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "implicit_grid"; }
  void run(StepContext& c) override;

 private:
  std::vector<ConstitutiveModelT<double>> models_;  // the bulk materials in double
  std::vector<GridShellKl> kls_;                    // per grid shell, in double
  double cap_ = 0;                                  ///< the adaptive step's cap [s]; 0: none
  std::uint64_t cap_epoch_ = 0;                     ///< the advance cap_ belongs to
};

}  // namespace shellmpm

// Stage "implicit_grid": with shot.integrator implicit, the grid's velocities come from a
// backward Euler solve (sim/implicit/grid_step.h) instead of grid_update's explicit
// momentum / mass + dt g (P2G then transfers no stress). A solve that does not converge is
// taken again at half the step, down to shot.dt_min; the step it took is left in
// StepContext::dt for the stages after it (colliders, G2P, plasticity) and the solver.
// Shells in contact are part of the solve (sim/implicit/grid_shells.h): their
// Kirchhoff-Love and contact energies at the control points the grid moves.
#pragma once
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
};

}  // namespace shellmpm

// Stage "implicit_shells": shells without contact, stepped by backward Euler
// (sim/implicit/shell_step.h) with shot.integrator implicit. A step whose Newton solve
// does not converge is taken again from the same state at half the step (every shell,
// so they stay in time together), down to shot.dt_min; the retries are counted in the
// frame's statistics, and the step the stage took is left in StepContext::dt.
#pragma once
#include <memory>
#include <vector>

#include "sim/implicit/shell_step.h"
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class ImplicitShellsStage final : public Stage {
 public:
  ImplicitShellsStage();
  ~ImplicitShellsStage() override;
  static bool needed(const Scene& s);
  std::string_view name() const override { return "implicit_shells"; }
  void run(StepContext& c) override;

 private:
  std::vector<std::unique_ptr<ShellImplicitStep>> steps_;  // per shell; null: on the grid
};

}  // namespace shellmpm

// Stage "implicit_shells": shells without contact, stepped by backward Euler
// (sim/implicit/shell_step.h) with shot.integrator implicit. A step whose Newton solve
// does not converge is taken again from the same state as two half steps (every shell,
// so they stay in time together), down to shot.dt_min; the retries are counted in the
// frame's statistics. The stage always covers the whole StepContext::dt (the grid's step,
// which implicit_grid may have shortened before it).
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
  /// Advances the shells without contact from t by dt (in halves where a solve fails).
  void advance(StepContext& c, double t, double dt);
  std::vector<std::unique_ptr<ShellImplicitStep>> steps_;  // per shell; null: on the grid
};

}  // namespace shellmpm

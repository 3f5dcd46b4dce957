// Stage "shell_update": Shells without contact: their control points integrate directly, no grid.
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class ShellUpdateStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "shell_update"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

// Stage "shell_forces": Kirchhoff-Love forces of every shell (with gravity for shells off the grid;
// on the grid gravity acts on the nodes) and the mass-proportional damping of contact shells.
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class ShellForcesStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "shell_forces"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

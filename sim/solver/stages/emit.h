// Stage "emit": Continuous emission: each emitting source adds the particles of this step.
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class EmitStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "emit"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

// Stage "denting": Denting plasticity of the shells (denting.h), with its plastic work.
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class DentingStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "denting"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

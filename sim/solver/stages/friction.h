// Stage "friction": The contact particles' Coulomb return mapping (friction_return_map.h), with its
// counts and the friction work.
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class FrictionStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "friction"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

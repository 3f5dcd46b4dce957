// Stage "colliders": Collider boundary conditions on grid nodes (each collider posed for this
// step).
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class CollidersStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "colliders"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

// Stage "colliders": Collider boundary conditions on grid nodes (each collider posed for this
// step).
#pragma once
#include <vector>

#include "sim/solver/stages/stage.h"

namespace shellmpm {

class CollidersStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "colliders"; }
  void run(StepContext& c) override;

 private:
  std::vector<double> work_;  ///< per grid block: the moving colliders' work this step [J]
};

}  // namespace shellmpm

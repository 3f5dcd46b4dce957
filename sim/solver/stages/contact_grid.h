// Stage "contact_grid": The contact particles' normal forces on the grid velocities, then the
// domain walls.
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class ContactGridStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "contact_grid"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

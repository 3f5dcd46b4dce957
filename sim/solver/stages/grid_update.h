// Stage "grid": Grid momentum to velocity, plus gravity; without contact shells also the domain
// walls (with them the walls come after the contact forces, in contact_grid).
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class GridUpdateStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "grid"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

// Stage "bin": Bins bulk particles and the contact shells' control and contact points by grid
// block.
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class BinStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "bin"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

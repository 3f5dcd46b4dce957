// Stage "plasticity": Plasticity of the bulk materials (Drucker-Prager sand, snow): runs of one
// material in storage order go through the SIMD batch return mapping.
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class BulkPlasticityStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "plasticity"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

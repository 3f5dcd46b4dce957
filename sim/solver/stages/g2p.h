// Stage "g2p": Grid to particle: velocities, APIC matrices and deformation gradients of bulk
// particles, control points and contact particles, each shell reading its own field where shells
// share nodes; then advection and the domain clamp.
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class G2pStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "g2p"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

// Stage "p2g": Particle to grid: bulk particles and control points (mass, APIC momentum, stress and
// forces), then each shell's own field where shells share nodes (shell_fields.h).
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class P2gStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "p2g"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

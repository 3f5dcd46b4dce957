// Stage "contact": Contact shells: pins prescribed for the step, contact particles placed from the
// control points, and their tangential forces added to the control-point forces (which move into
// the GridShell for the transfer). Implicit: pins and positions only (the forces are part of
// the grid solve, implicit_grid).
#pragma once
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class ContactForcesStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "contact"; }
  void run(StepContext& c) override;
};

}  // namespace shellmpm

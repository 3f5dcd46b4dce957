// A step-by-step view of the energy audit (sim/integrity/energy_audit.h), for finding
// which stage of a step puts in energy the audit cannot trace. With SHELLMPM_ENERGY_TRACE=1
// in the environment, each stage that changes the balance (the bodies' energy plus what
// was dissipated, less what was supplied) by more than 1e-4 J prints one line to stderr:
// the time, the stage, the change, and the body whose energy changed most, split into
// kinetic, stored and potential. Between p2g and g2p the bodies' state is on the grid, so
// a solve's effect shows in g2p. Off, it costs one branch per stage.
#pragma once
#include <string_view>
#include <vector>

#include "sim/integrity/energy_audit.h"
#include "sim/solver/step_context.h"

namespace shellmpm {

class EnergyTrace {
 public:
  EnergyTrace();
  bool on() const { return on_; }
  /// The balance at the start of a step.
  void begin(const StepContext& c);
  /// After a stage: prints its change when above the threshold.
  void after(const StepContext& c, std::string_view stage);

 private:
  double balance(const StepContext& c, std::vector<BodyEnergy>& bodies) const;
  bool on_ = false;
  double last_ = 0;
  std::vector<BodyEnergy> bodies_;
};

}  // namespace shellmpm

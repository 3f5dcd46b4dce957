// Stage "shell_guard": the last approach of contact shells closer than a gap the grid
// cannot hold (sim/contact/shell_guard.h), after G2P has moved the control points.
#pragma once
#include "sim/contact/shell_guard.h"
#include "sim/solver/stages/stage.h"

namespace shellmpm {

class ShellGuardStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  /// The gap the scene asks for: shot.shell_guard_gap, or its default [m].
  static double gap(const Scene& s);
  /// The gap kept between bulk particles and shells [m]: gap(s), or with contact at the
  /// surfaces and no shot.shell_guard_gap at most half the thinnest contact layer.
  static double bulk_gap(const Scene& s);
  std::string_view name() const override { return "shell_guard"; }
  void run(StepContext& c) override;

 private:
  ShellGuard guard_;
  bool ready_ = false;
};

}  // namespace shellmpm

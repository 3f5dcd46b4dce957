// Stage "friction": The contact particles' Coulomb return mapping (friction_return_map.h), with its
// counts and the friction work.
#pragma once
#include <cstdint>
#include <vector>

#include "sim/solver/stages/stage.h"

namespace shellmpm {

class FrictionStage final : public Stage {
 public:
  static bool needed(const Scene& s);
  std::string_view name() const override { return "friction"; }
  void run(StepContext& c) override;

 private:
  std::vector<std::vector<std::uint8_t>> release_;  ///< per grid shell and site (scratch)
};

}  // namespace shellmpm

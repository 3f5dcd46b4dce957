#include "sim/solver/stages/denting.h"

#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool DentingStage::needed(const Scene& s) {
  return any_denting_shell(s);
}

void DentingStage::run(StepContext& c) {
  for (auto& sh : c.shells) c.plastic_work += sh->project_plasticity(c.opt.serial);
}

}  // namespace shellmpm

#include "sim/solver/stages/denting.h"

#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool DentingStage::needed(const Scene& s) {
  return any_denting_shell(s);
}

void DentingStage::run(StepContext& c) {
  for (auto& sh : c.shells) {
    const double w = sh->project_plasticity(c.opt.serial);
    c.plastic_work += w;
    c.add_dissipation(sh.get(), w);
  }
}

}  // namespace shellmpm

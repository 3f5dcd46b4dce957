#include "sim/solver/stages/friction.h"

#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool FrictionStage::needed(const Scene& s) {
  return any_contact_shell(s);
}

void FrictionStage::run(StepContext& c) {
  ContactStepStats total;
  for (GridShell& g : c.grid_shells) {
    const ContactStepStats st = g.contact->return_map(g.shell->x.data(), c.opt.serial);
    total.compressed += st.compressed;
    total.sliding += st.sliding;
    total.friction_work += st.friction_work;
    total.separation_work += st.separation_work;
  }
  c.friction_work += total.friction_work;
  c.contact_step = total;
}

}  // namespace shellmpm

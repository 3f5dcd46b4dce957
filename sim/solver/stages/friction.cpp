#include "sim/solver/stages/friction.h"

#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool FrictionStage::needed(const Scene& s) {
  return any_contact_shell(s);
}

void FrictionStage::run(StepContext& c) {
  ContactStepStats total;
  // With contact at the surfaces, sites apart from every other body drop the compression
  // that reading its velocity across the gap gave them (ShellFields::apart_sites).
  const bool release = c.shell_fields.contact_at_surfaces() && !c.shell_points.empty();
  if (release) {
    release_.resize(c.grid_shells.size());
    for (std::size_t s = 0; s < c.grid_shells.size(); ++s)
      release_[s].assign(c.grid_shells[s].contact->num_sites(), 0);
    c.shell_fields.apart_sites(c.grid, c.shell_table, c.shell_points, release_, c.opt.serial);
  }
  for (std::size_t s = 0; s < c.grid_shells.size(); ++s) {
    GridShell& g = c.grid_shells[s];
    const ContactStepStats st = g.contact->return_map(g.shell->x.data(), c.opt.serial,
                                                      release ? release_[s].data() : nullptr);
    total.compressed += st.compressed;
    total.sliding += st.sliding;
    total.friction_work += st.friction_work;
    c.add_dissipation(g.shell, st.friction_work);
    total.separation_work += st.separation_work;
  }
  c.friction_work += total.friction_work;
  c.contact_step = total;
}

}  // namespace shellmpm

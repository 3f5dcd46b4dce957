#include "sim/solver/stages/shell_guard.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {
namespace {
/// With contact at the surfaces, how far below the thinnest contact layer c the guard's
/// default gap lies: kSurfaceGuardShare c, or kSurfaceGuardCells dx below c where that is
/// closer (a thick layer).
constexpr double kSurfaceGuardShare = 0.8;
constexpr double kSurfaceGuardCells = 0.05;

/// The thinnest and thickest contact layer among the shells in contact: infinity and 0
/// where no shell has contact.
struct ContactLayers {
  double thinnest = std::numeric_limits<double>::infinity();
  double thickest = 0;
};

ContactLayers contact_layers(const Scene& s) {
  ContactLayers l;
  for (std::size_t i = 0; i < s.shells.size(); ++i) {
    if (!shell_has_contact(s, i)) continue;
    const ShellMaterialDesc& m = s.shell_materials[static_cast<std::size_t>(s.shells[i].material)];
    const double c = m.contact_thickness.value_or(m.thickness);
    l.thinnest = std::min(l.thinnest, c);
    l.thickest = std::max(l.thickest, c);
  }
  return l;
}
}  // namespace

bool ShellGuardStage::needed(const Scene& s) {
  return s.shot.shell_guard && any_contact_shell(s);
}

double ShellGuardStage::gap(const Scene& s) {
  if (s.shot.shell_guard_gap > 0) return s.shot.shell_guard_gap;
  const ContactLayers l = contact_layers(s);
  const double dx = s.shot.dx;
  // Stencil contact: the larger of 0.05 dx and the thickest contact shell.
  if (s.shot.contact_at != ContactAt::Surface) return std::max(0.05 * dx, l.thickest);
  // Surface contact holds bodies at their contact thickness on the grid, so the guard, a
  // backstop with Coulomb friction, stays just below it: c - min(0.2 c, 0.05 dx) for the
  // thinnest contact layer c (the formula grows with c). At half of c a strip wrung by
  // four turns (scenes/stress/strip_twist_4turns.yaml), whose layers only the guard holds
  // where three meet in a stencil, crossed itself at frame 59. A layer of half a cell or
  // more is held by the grid only in part (the upper sheet's stencil reaches nodes the
  // lower one's does not, whose velocity the pair rule does not hold): the sheets sank
  // 0.13 and 0.39 dx below layers of 0.5 and 1 dx onto a guard at half of c. The guard,
  // 0.05 dx under the layer and with friction, holds that last part.
  if (!std::isfinite(l.thinnest)) return 0.05 * dx;
  const double c = l.thinnest;
  return c - std::min((1 - kSurfaceGuardShare) * c, kSurfaceGuardCells * dx);
}

double ShellGuardStage::bulk_gap(const Scene& s) {
  const double g = gap(s);
  if (s.shot.shell_guard_gap > 0 || s.shot.contact_at != ContactAt::Surface) return g;
  // A bulk particle's centre rests half its contact layer plus half a particle spacing
  // out from a shell's limit surface: half the thinnest layer stays below that.
  const ContactLayers l = contact_layers(s);
  return std::isfinite(l.thinnest) ? std::min(g, 0.5 * l.thinnest) : g;
}

void ShellGuardStage::run(StepContext& c) {
  if (!ready_) {
    guard_.setup(c.grid_shells, gap(c.scene), c.opt.serial);
    if (c.scene.shot.contact_at == ContactAt::Surface) {
      guard_.set_friction(true);
      guard_.set_bulk_gap(bulk_gap(c.scene));
    }
    ready_ = true;
  }
  GuardBulk bulk;
  if (c.particles.size() > 0) {
    bulk.particles = &c.particles;
    bulk.densities = &c.densities;
    bulk.epoch = c.particle_epoch;
  }
  const ShellGuardStats st = guard_.apply(c.grid_shells, c.shell_x_start, bulk, c.dt);
  c.energy_supplied += st.pin_work;
  ShellGuardStats& f = c.guard_frame;
  f.pairs = std::max(f.pairs, st.pairs);
  f.impulses += st.impulses;
  f.zoned += st.zoned;
  f.unresolved += st.unresolved;
  f.sweeps = std::max(f.sweeps, st.sweeps);
}

}  // namespace shellmpm

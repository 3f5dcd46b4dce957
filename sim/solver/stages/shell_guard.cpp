#include "sim/solver/stages/shell_guard.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {
namespace {
/// With contact at the surfaces, the guard's default gap as a share of the thinnest
/// contact layer.
constexpr double kSurfaceGuardShare = 0.8;
}  // namespace

bool ShellGuardStage::needed(const Scene& s) {
  return s.shot.shell_guard && any_contact_shell(s);
}

double ShellGuardStage::gap(const Scene& s) {
  if (s.shot.shell_guard_gap > 0) return s.shot.shell_guard_gap;
  const bool surface = s.shot.contact_at == ContactAt::Surface;
  // Stencil contact: the larger of 0.05 dx and the thickest contact shell. Surface contact
  // holds bodies at their contact thickness on the grid, so the guard, a frictionless
  // backstop, stays below it: four fifths of the thinnest contact layer. At half of it a
  // strip wrung by four turns (scenes/stress/strip_twist_4turns.yaml), whose layers only
  // the guard holds where three meet in a stencil, crossed itself at frame 59.
  double g = surface ? std::numeric_limits<double>::infinity() : 0.05 * s.shot.dx;
  for (std::size_t i = 0; i < s.shells.size(); ++i) {
    if (!shell_has_contact(s, i)) continue;
    const ShellMaterialDesc& m = s.shell_materials[static_cast<std::size_t>(s.shells[i].material)];
    const double c = m.contact_thickness.value_or(m.thickness);
    g = surface ? std::min(g, kSurfaceGuardShare * c) : std::max(g, c);
  }
  return std::isfinite(g) ? g : 0.05 * s.shot.dx;
}

void ShellGuardStage::run(StepContext& c) {
  if (!ready_) {
    guard_.setup(c.grid_shells, gap(c.scene), c.opt.serial);
    ready_ = true;
  }
  GuardBulk bulk;
  if (c.particles.size() > 0) {
    bulk.particles = &c.particles;
    bulk.densities = &c.densities;
    bulk.epoch = c.particle_epoch;
  }
  const ShellGuardStats st = guard_.apply(c.grid_shells, c.shell_x_start, bulk, c.dt);
  ShellGuardStats& f = c.guard_frame;
  f.pairs = std::max(f.pairs, st.pairs);
  f.impulses += st.impulses;
  f.zoned += st.zoned;
  f.unresolved += st.unresolved;
  f.sweeps = std::max(f.sweeps, st.sweeps);
}

}  // namespace shellmpm

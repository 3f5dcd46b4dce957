#include "sim/solver/stages/emit.h"

#include "sim/solver/stages/scene_rules.h"

namespace shellmpm {

bool EmitStage::needed(const Scene& s) {
  return any_emitting_source(s);
}

void EmitStage::run(StepContext& c) {
  for (std::size_t i = 0; i < c.samplers.size(); ++i) {
    if (!c.scene.sources[i].emit) continue;
    std::vector<Vec3d> pts;
    c.samplers[i].emit(c.time, c.dt, [&](const Vec3d& p) { pts.push_back(p); });
    c.add_particles_from(i, pts);
    // What the new particles bring (energy_audit.h): kinetic and potential energy.
    const SourceDesc& src = c.scene.sources[i];
    const double m = c.samplers[i].particle_volume() * c.densities[src.material];
    const Vec3d g = c.scene.shot.gravity;
    for (const Vec3d& p : pts)
      c.energy_supplied += m * (0.5 * src.velocity.squaredNorm() - g.dot(p));
  }
}

}  // namespace shellmpm

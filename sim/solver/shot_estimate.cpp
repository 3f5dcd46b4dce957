#include "sim/solver/shot_estimate.h"

#include <algorithm>
#include <cmath>

#include "sim/solver/solver.h"

namespace shellmpm {

ShotEstimate estimate_shot(const Solver& solver, double peak_bulk_particles, int threads) {
  ShotEstimate e;
  const Scene& scene = solver.scene();
  e.threads = std::max(1, threads);
  e.limits = step_limits(solver, /*upcoming=*/true);
  e.dt = e.limits.front().dt;
  e.substeps_per_frame = std::ceil(1.0 / scene.shot.fps / e.dt);
  for (const ConstitutiveModel& m : solver.models())
    e.snow_step_shrink =
        std::max(e.snow_step_shrink, static_cast<double>(std::sqrt(m.max_hardening())));
  const double per_thread_step = e.substeps_per_frame / e.threads;
  e.bulk_seconds = per_thread_step * peak_bulk_particles * kBulkParticleStepSeconds;
  for (std::size_t i = 0; i < solver.shells().size(); ++i) {
    const ShellObject& sh = *solver.shells()[i];
    const ShellMaterialDesc& m = scene.shell_materials[sh.desc().material];
    const double layers =
        static_cast<double>(sh.triangles().size()) * m.quadrature_inplane * m.quadrature_thickness;
    e.shell_seconds += per_thread_step * layers * kShellLayerSeconds;
    if (const ShellContact* c = solver.contact(i)) {
      const double points = static_cast<double>(sh.size() + c->num_sites());
      e.contact_seconds += per_thread_step * points * kContactPointStepSeconds;
    }
  }
  return e;
}

}  // namespace shellmpm

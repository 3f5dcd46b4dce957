#include <cstdio>

#include "app/commands.h"
#include "app/scene_loading.h"
#include "sim/core/parallel.h"
#include "sim/solver/solver.h"
#include "sim/solver/step_limits.h"

namespace shellmpm {

int check_command(const CommonArgs& a) {
  LoadedScene ls = load_scene_for_cli(a, "", "");
  const Scene& scene = ls.scene;
  ThreadLimit limit(scene.shot.threads);
  Solver solver(scene);
  const ShotSettings& s = scene.shot;
  std::printf("scene %s: valid\n", scene.path.c_str());
  std::printf("frames %d-%d at %g fps, dx %g m, domain [%g %g %g]..[%g %g %g]\n", s.frame_start,
              s.frame_end, s.fps, s.dx, s.domain_min.x(), s.domain_min.y(), s.domain_min.z(),
              s.domain_max.x(), s.domain_max.y(), s.domain_max.z());
  std::string stages;
  for (const std::string& n : solver.stage_names()) stages += (stages.empty() ? "" : ", ") + n;
  std::printf("stages: %s\n", stages.empty() ? "(none: nothing to simulate)" : stages.c_str());
  std::size_t emitted = 0;
  for (std::size_t i = 0; i < scene.sources.size(); ++i) {
    const SourceDesc& src = scene.sources[i];
    if (!src.emit) continue;
    // Flow over the window: lattice points leaving the shape, estimated by a dry run.
    const SourceSampler& sm = solver.samplers()[i];
    const double step = 1.0 / s.fps;
    for (double t = sm.emit_t0(); t < sm.emit_t1(); t += step)
      sm.emit(t, std::min(step, sm.emit_t1() - t), [&](const Vec3d&) { ++emitted; });
  }
  for (std::size_t si = 0; si < solver.shells().size(); ++si) {
    const auto& sh = solver.shells()[si];
    const ShellMaterialDesc& m = scene.shell_materials[sh->desc().material];
    std::printf("shell %s: %zu control points, %zu output vertices, %d x %d quadrature points per "
                "triangle, stable step %.3g s%s\n",
                sh->name().c_str(), sh->size(), sh->limit_mesh().num_vertices(),
                m.quadrature_inplane, m.quadrature_thickness, sh->stable_dt(s.cfl),
                m.yield_stress > 0 ? ", denting" : "");
    if (const ShellContact* c = solver.contact(si)) {
      // Mean rest edge of the control mesh against dx (METHOD.md: keep them close; a grid
      // much coarser than the mesh leaves gaps between shells in contact, a much finer
      // one lets contact particles miss the control points' grid nodes).
      double sum = 0;
      std::size_t n = 0;
      for (const auto& t : sh->triangles())
        for (int e = 0; e < 3; ++e, ++n) sum += (sh->rest[t[e]] - sh->rest[t[(e + 1) % 3]]).norm();
      const double h = n ? sum / static_cast<double>(n) : 0;
      std::printf("  contact: %zu contact particles (%d per triangle), k_c %g Pa, gamma %g Pa, "
                  "friction %g; mean edge %.3g m = %.2f dx\n",
                  c->num_sites(), m.contact_samples, c->params().kc, c->params().gamma,
                  c->params().friction, h, h / s.dx);
      if (h > 2.0 * s.dx || h < 0.5 * s.dx)
        std::printf("warning: shell %s: its mesh spacing (%.3g m) is %s than the grid spacing dx = "
                    "%g m; keep them within a factor 2 (%s)\n",
                    sh->name().c_str(), h, h > s.dx ? "much coarser" : "much finer", s.dx,
                    h > s.dx ? "refine the mesh or raise dx" : "coarsen the mesh or lower dx");
    } else {
      std::printf("  contact: off (the shell moves on its own, without the grid)\n");
    }
  }
  const std::size_t n0 = solver.particles().size();
  std::printf("particles: %zu at start, about %zu more emitted\n", n0, emitted);
  // Bin once to count grid blocks (no simulation).
  SparseGrid grid;
  grid.setup(s.dx, s.domain_min);
  grid.bin(solver.particles().x);
  std::printf("grid blocks: %zu (4x4x4 nodes) around %zu particle blocks\n", grid.num_grid_blocks(),
              grid.num_particle_blocks());
  const std::size_t peak = n0 + emitted;
  // Bytes per particle from the particle arrays plus the grid share measured in
  // bench/mpm_throughput (about 21 B/particle at 8 particles per cell).
  const double per_particle = static_cast<double>(sizeof(Vec3) * 2 + sizeof(Mat3) * 2 +
                                                  sizeof(Real) * 2 + 2 + 4) + 8.0;
  const double grid_bytes = n0 > 0 ? static_cast<double>(grid.bytes()) / n0 : 21.0;
  const double mem = (per_particle + grid_bytes) * static_cast<double>(peak);
  std::printf("memory: about %.1f MiB at the peak of %zu particles\n", mem / (1024.0 * 1024.0), peak);
  // The step: the solver's bounds on the current particles and shells, plus the speeds
  // and wave speeds (at rest) of what the sources are still to emit.
  const std::vector<StepLimit> limits = step_limits(solver, /*upcoming=*/true);
  const double dt = limits.front().dt;
  const double steps = std::ceil(1.0 / s.fps / dt);
  double harden = 1;
  for (const ConstitutiveModel& m : solver.models())
    harden = std::max(harden, static_cast<double>(std::sqrt(m.max_hardening())));
  if (harden > 1.01)
    std::printf("note: compressed snow hardens; its step can get up to %.1fx smaller than this\n",
                harden);
  // Throughput from bench/mpm_throughput on the reference machine, per thread.
  constexpr double kParticleStepsPerSecondPerThread = 2.5e6;
  const int threads = ThreadLimit::active();
  const double sec =
      steps * static_cast<double>(peak) / (kParticleStepsPerSecondPerThread * threads);
  std::printf("time step: about %.3g s (%g substeps per frame)\n", dt, steps);
  // What sets it: the smallest bounds, smallest first.
  for (std::size_t i = 0; i < limits.size() && i < 3; ++i)
    std::printf("%s%s (%.2g s)\n",
                i == 0 ? "time step limited by: " : "  then: ", limits[i].detail.c_str(),
                limits[i].dt);
  std::printf("estimated time per frame at the peak: %.2f s on %d threads (at %.1fM particle-steps/s/thread)\n",
              sec, threads, kParticleStepsPerSecondPerThread / 1e6);
  // A step below dt_min stops the run; say so now, with the cause (a warning: exit 0).
  if (dt < s.dt_min)
    std::printf(
        "warning: the stable step %.2g s is below shot.dt_min = %g s, so `shellmpm run` "
        "will stop %s; %s\n",
        dt, s.dt_min, limits.front().upcoming ? "once the sources emit" : "at t = 0",
        describe_step_limits(limits, s.dt_min).c_str());
  return kExitOk;
}

}  // namespace shellmpm

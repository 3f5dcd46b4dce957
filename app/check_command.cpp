#include <cstdio>

#include "app/commands.h"
#include "app/scene_loading.h"
#include "io/scene_quality.h"
#include "shot/available_memory.h"
#include "sim/core/parallel.h"
#include "sim/scene/scene_words.h"
#include "sim/solver/shot_estimate.h"
#include "sim/solver/solver.h"
#include "sim/solver/stages/shell_guard.h"
#include "sim/solver/step_limits.h"
#include "study/preset_errors.h"

namespace shellmpm {
namespace {

/// check builds the shot (for its stages, shells and time step) only up to this estimate,
/// and only when it also fits in half the available memory; beyond, it reports what it can
/// from the scene alone.
constexpr double kCheckBuildLimit = 2.0 * 1024 * 1024 * 1024;

/// Counts and memory, from the scene alone (nothing of the shot is allocated).
void print_estimate(const RunMemory& mem, const AvailableMemory& avail) {
  const MemoryCounts& n = mem.solver.counts;
  std::printf("particles: about %.0f at start, about %.0f more emitted\n", n.fill_particles,
              n.emitted_particles);
  if (n.shell_points > 0)
    std::printf(
        "shells: %.0f control points, %.0f triangles, %.0f quadrature points, %.0f "
        "contact particles\n",
        n.shell_points, n.shell_triangles, n.quadrature_points, n.contact_sites);
  std::printf("grid blocks: about %.0f (4x4x4 nodes) around %.0f particle blocks\n", n.grid_blocks,
              n.particle_blocks);
  std::string parts;
  for (const MemoryPart& p : mem.solver.parts)
    if (p.bytes >= 0.01 * mem.peak)
      parts += (parts.empty() ? "" : ", ") + p.what + " " + format_bytes(p.bytes);
  if (mem.writers >= 0.01 * mem.peak)
    parts += (parts.empty() ? "" : ", ") + mem.writer + " writer " + format_bytes(mem.writers);
  if (mem.solver.construction_bytes >
      mem.solver.held_bytes + std::max(mem.solver.step_scratch, mem.writers))
    parts += (parts.empty() ? "" : ", ") + std::string("peak while building the shells ") +
             format_bytes(mem.solver.construction_bytes);
  std::printf("memory: about %s at the peak (this process now %s; %s)\n",
              format_bytes(mem.peak).c_str(), format_bytes(mem.baseline).c_str(),
              parts.empty() ? "nothing else" : parts.c_str());
  const double need = mem.peak - mem.baseline;
  if (avail.known && need > avail.bytes)
    std::printf(
        "warning: that is %s more than now, and only %s is available (%s): "
        "`shellmpm run` will refuse it (run --force tries anyway)\n",
        format_bytes(need).c_str(), format_bytes(avail.bytes).c_str(), avail.source.c_str());
}

/// Each shell's points, quadrature, stable step and contact, with a warning when its mesh
/// spacing and dx are far apart.
void print_shells(const Solver& solver) {
  const Scene& scene = solver.scene();
  const ShotSettings& s = scene.shot;
  for (std::size_t si = 0; si < solver.shells().size(); ++si) {
    const auto& sh = solver.shells()[si];
    const ShellMaterialDesc& m = scene.shell_materials[sh->desc().material];
    std::printf(
        "shell %s: %zu control points, %zu output vertices, %d x %d quadrature points per "
        "triangle, stable step %.3g s%s\n",
        sh->name().c_str(), sh->size(), sh->limit_mesh().num_vertices(), m.quadrature_inplane,
        m.quadrature_thickness, sh->stable_dt(s.cfl), m.yield_stress > 0 ? ", denting" : "");
    if (const ShellContact* c = solver.contact(si)) {
      // Mean rest edge of the control mesh against dx (METHOD.md: keep them close; a grid
      // much coarser than the mesh leaves gaps between shells in contact, a much finer
      // one lets contact particles miss the control points' grid nodes).
      double sum = 0;
      std::size_t n = 0;
      for (const auto& t : sh->triangles())
        for (int e = 0; e < 3; ++e, ++n) sum += (sh->rest[t[e]] - sh->rest[t[(e + 1) % 3]]).norm();
      const double h = n ? sum / static_cast<double>(n) : 0;
      std::printf(
          "  contact: %zu contact particles (%d per triangle), k_c %g Pa, gamma %g Pa, "
          "friction %g; mean edge %.3g m = %.2f dx\n",
          c->num_sites(), m.contact_samples, c->params().kc, c->params().gamma,
          c->params().friction, h, h / s.dx);
      if (h > 2.0 * s.dx || h < 0.5 * s.dx)
        std::printf(
            "warning: shell %s: its mesh spacing (%.3g m) is %s than the grid spacing dx = "
            "%g m; keep them within a factor 2 (%s)\n",
            sh->name().c_str(), h, h > s.dx ? "much coarser" : "much finer", s.dx,
            h > s.dx ? "refine the mesh or raise dx" : "coarsen the mesh or lower dx");
    } else {
      std::printf("  contact: off (the shell moves on its own, without the grid)\n");
    }
  }
}

/// The step, what sets it, and the time a frame costs; a warning when the step is below
/// dt_min (the run would stop).
void print_time(const Solver& solver, const RunMemory& mem) {
  const ShotSettings& s = solver.scene().shot;
  if (!s.integrator_reason.empty())
    std::printf("integrator: auto chose %s: %s\n", word_of(s.integrator).c_str(),
                s.integrator_reason.c_str());
  if (s.integrator == Integrator::Implicit) {
    if (s.shell_fields_in_solve) std::printf("warning: %s\n", kFieldsInSolveWarning);
    // No wave-speed bound: the step follows motion, the frame and the Newton solves.
    char method[64] = "backward Euler";
    if (s.implicit_theta < 1)
      std::snprintf(method, sizeof method, "theta method, theta %g, for shells without contact",
                    s.implicit_theta);
    std::printf(
        "integrator: implicit (%s, Newton with PCG, %s preconditioner): steps of "
        "up to dt_max = %.3g s (%.3g per frame), shortened where cfl dx / max speed is "
        "smaller and halved where a Newton solve does not converge to %g m/s in %d "
        "iterations; the time per frame depends on those solves (stats.json: implicit)\n",
        method, word_of(s.implicit_preconditioner).c_str(), s.dt_max, s.dt_max * s.fps,
        s.implicit_tolerance, s.newton_max_iterations);
    (void)mem;
    return;
  }
  // The step and what a frame costs: the solver's bounds on the current particles and
  // shells, plus the speeds and wave speeds (at rest) of what the sources are still to emit.
  const ShotEstimate est =
      estimate_shot(solver, mem.solver.counts.peak_particles(), ThreadLimit::active());
  const std::vector<StepLimit>& limits = est.limits;
  const double dt = est.dt;
  if (est.snow_step_shrink > 1.01)
    std::printf("note: compressed snow hardens; its step can get up to %.1fx smaller than this\n",
                est.snow_step_shrink);
  std::printf("time step: about %.3g s (%g substeps per frame)\n", dt, est.substeps_per_frame);
  // What sets it: the smallest bounds, smallest first.
  for (std::size_t i = 0; i < limits.size() && i < 3; ++i)
    std::printf("%s%s (%.2g s)\n",
                i == 0 ? "time step limited by: " : "  then: ", limits[i].detail.c_str(),
                limits[i].dt);
  std::printf(
      "estimated time per frame at the peak: %.2f s on %d threads (bulk particles %.2f s, "
      "shell forces %.2f s, contact %.2f s; at the benchmarks' throughput per thread)\n",
      est.seconds_per_frame(), est.threads, est.bulk_seconds, est.shell_seconds,
      est.contact_seconds);
  // A step below dt_min stops the run; say so now, with the cause (a warning: exit 0).
  if (dt < s.dt_min)
    std::printf(
        "warning: the stable step %.2g s is below shot.dt_min = %g s, so `shellmpm run` "
        "will stop %s; %s\n",
        dt, s.dt_min, limits.front().upcoming ? "once the sources emit" : "at t = 0",
        describe_step_limits(limits, s.dt_min).c_str());
}

/// The preset's resolved values (what it set), then what the accuracy study measured with it
/// on the reference problems nearest to this scene.
void print_quality(const Scene& scene) {
  if (!scene.shot.quality) return;
  const Quality q = *scene.shot.quality;
  const QualityPreset p = quality_preset(q);
  std::printf(
      "quality %s: dx %g m (%.3gx the scene's), sheet and cylinder resolutions / %.3g; cfl %g",
      word_of(q).c_str(), scene.shot.dx, p.dx_factor, p.dx_factor, scene.shot.cfl);
  for (const ShellMaterialDesc& m : scene.shell_materials)
    std::printf("; %s: quadrature %d x %d, contact samples %d", m.name.c_str(),
                m.quadrature_inplane, m.quadrature_thickness, m.contact_samples);
  for (const SourceDesc& src : scene.sources)
    std::printf("; %s: %g particles per cell", src.name.c_str(), src.particles_per_cell);
  std::printf(" (keys the scene sets itself keep their values)\n");
  // The full study's results, or a presets-only study's (`study --sweep "quality preset"`).
  std::string results = std::string(SHELLMPM_SOURCE_DIR) + "/docs/accuracy/results.json";
  std::vector<PresetMeasurement> m = preset_measurements(results, q, nearest_problems(scene));
  if (m.empty()) {
    results = std::string(SHELLMPM_SOURCE_DIR) + "/docs/accuracy/presets/results.json";
    m = preset_measurements(results, q, nearest_problems(scene));
  }
  if (m.empty()) {
    std::printf("  no study results for this preset in %s (run `shellmpm study`)\n",
                results.c_str());
    return;
  }
  std::printf("  measured with this preset (docs/accuracy.md):");
  for (const PresetMeasurement& x : m) {
    std::printf(" %s %s", x.problem.c_str(), x.error.c_str());
    if (x.cost_vs_production > 0) std::printf(" at %.2gx production's time", x.cost_vs_production);
    std::printf(";");
  }
  std::printf("\n");
}

}  // namespace

int check_command(const CommonArgs& a) {
  LoadedScene ls = load_scene_for_cli(a, "", "");
  const Scene& scene = ls.scene;
  ThreadLimit limit(scene.shot.threads);
  const ShotSettings& s = scene.shot;
  std::printf("scene %s: valid\n", scene.path.c_str());
  std::printf("frames %d-%d at %g fps, dx %g m, domain [%g %g %g]..[%g %g %g]\n", s.frame_start,
              s.frame_end, s.fps, s.dx, s.domain_min.x(), s.domain_min.y(), s.domain_min.z(),
              s.domain_max.x(), s.domain_max.y(), s.domain_max.z());
  print_quality(scene);
  const RunMemory mem = estimate_memory(ls);
  const AvailableMemory avail = available_memory();
  print_estimate(mem, avail);
  const double need = mem.peak - mem.baseline;
  if (mem.peak > kCheckBuildLimit || (avail.known && need > 0.5 * avail.bytes)) {
    std::printf(
        "note: check does not build a shot this large (over %s, or over half the "
        "available memory): its stages and time step are not estimated; `shellmpm "
        "run` reports them\n",
        format_bytes(kCheckBuildLimit).c_str());
    return kExitOk;
  }

  Solver solver(scene);
  std::string stages;
  for (const std::string& n : solver.stage_names()) stages += (stages.empty() ? "" : ", ") + n;
  std::printf("stages: %s\n", stages.empty() ? "(none: nothing to simulate)" : stages.c_str());
  if (ShellGuardStage::needed(scene))
    std::printf("shell guard: gap %g m (%s)\n", ShellGuardStage::gap(scene),
                scene.shot.shell_guard_gap > 0 ? "shot.shell_guard_gap"
                : scene.shot.contact_at == ContactAt::Surface
                    ? "the thinnest contact layer less a fifth of it or 0.05 dx"
                    : "0.05 dx or the thickest contact shell");
  print_shells(solver);
  print_time(solver, mem);
  return kExitOk;
}

}  // namespace shellmpm

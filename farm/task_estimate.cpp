#include "farm/task_estimate.h"

#include <algorithm>
#include <cmath>

#include "io/mesh_sdf.h"
#include "io/scene_bounds.h"
#include "io/scene_reader.h"
#include "io/shell_assets.h"
#include "io/user_error.h"
#include "shot/run_memory.h"
#include "sim/solver/integrator_choice.h"
#include "sim/solver/shot_estimate.h"
#include "sim/solver/solver.h"

namespace shellmpm {
namespace {

/// As `check`: the shot is built for its time estimate only up to this memory estimate.
constexpr double kBuildLimit = 2.0 * 1024 * 1024 * 1024;

}  // namespace

TaskEstimate estimate_task(const BatchTask& t, int threads, double baseline) {
  std::vector<std::string> sets;
  for (const Override& o : t.overrides) sets.push_back(o.arg());
  Scene scene;
  try {
    scene = read_scene(t.scene, sets);
    scene.shot.frame_start = t.frame_start;
    scene.shot.frame_end = t.frame_end;
    scene.shot.threads = threads;
    load_scene_assets(scene);
    load_shell_meshes(scene);
    check_scene_bounds(scene);
    resolve_integrator(scene);
  } catch (const UserError& e) {
    rethrow_for_task(e, t);
  }
  TaskEstimate est;
  const RunMemory mem = estimate_run_memory(scene, baseline);
  est.memory_bytes = mem.peak;
  est.checkpoint_bytes = mem.writers;
  if (mem.peak > kBuildLimit || scene.shot.integrator == Integrator::Implicit) return est;
  const Solver solver(scene);
  const ShotEstimate shot = estimate_shot(solver, mem.solver.counts.peak_particles(), threads);
  est.seconds_per_frame = shot.seconds_per_frame();
  est.seconds = est.seconds_per_frame * std::max(0, t.frame_end - 1);
  if (shot.dt < scene.shot.dt_min)
    est.warning = "the stable step " + std::to_string(shot.dt) +
                  " s is below shot.dt_min: " + "`shellmpm check` says why; the run would stop";
  return est;
}

int signal_margin_seconds(const TaskEstimate& e) {
  const double frame = std::max(0.0, e.seconds_per_frame);
  const double s = 2 * frame + e.checkpoint_bytes / 50e6 + 60;
  return static_cast<int>(std::clamp(std::ceil(s), 90.0, 65535.0));
}

}  // namespace shellmpm

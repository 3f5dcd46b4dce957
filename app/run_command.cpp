#include <cstdio>

#include "app/commands.h"
#include "app/scene_loading.h"
#include "io/shot_runner.h"
#include "sim/core/parallel.h"

namespace shellmpm {

int run_command(const RunArgs& a) {
  LoadedScene ls = load_scene_for_cli(a, a.frames, a.output);
  const Scene& scene = ls.scene;
  ThreadLimit limit(scene.shot.threads);
  Progress progress(a.verbosity, scene.shot.frame_start, scene.shot.frame_end);
  if (a.verbosity == Verbosity::Verbose)
    progress.message("threads: " + std::to_string(ThreadLimit::active()));
  RunOptions ro;
  ro.resume = a.resume;
  ro.scene_fingerprint = ls.fingerprint;
  ro.on_substep = [&](int f, int s, double dt, double t, std::size_t n) {
    progress.substep(f, s, dt, t, n);
  };
  ro.on_frame = [&](const FrameStats& s) {
    if (s.frame >= scene.shot.frame_start) progress.frame_done(s);
  };
  ro.log = [&](const std::string& m) { progress.message(m); };
  const int n = run_shot(scene, ro);
  progress.finish();
  progress.message("wrote " + std::to_string(n) + " frames to " + scene.output.directory);
  return kExitOk;
}

}  // namespace shellmpm

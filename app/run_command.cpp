#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "app/commands.h"
#include "app/scene_loading.h"
#include "io/shot_runner.h"
#include "render/preview_job.h"
#include "render/run_manifest.h"
#include "sim/core/parallel.h"

namespace shellmpm {

int run_command(const RunArgs& a) {
  LoadedScene ls = load_scene_for_cli(a, a.frames, a.output);
  const Scene& scene = ls.scene;
  prepare_run(ls, a.force, a.preview || scene.render.preview);
  ThreadLimit limit(scene.shot.threads);
  Progress progress(a.verbosity, scene.shot.frame_start, scene.shot.frame_end);
  if (a.verbosity == Verbosity::Verbose)
    progress.message("threads: " + std::to_string(ThreadLimit::active()));
  // run.json lets `shellmpm render OUTDIR` find the scene later.
  {
    std::error_code ec;
    std::filesystem::create_directories(scene.output.directory, ec);
    if (std::filesystem::is_directory(scene.output.directory, ec)) {
      RunManifest m;
      m.scene_path = std::filesystem::absolute(a.scene).lexically_normal().string();
      std::ifstream in(a.scene, std::ios::binary);
      std::stringstream text;
      text << in.rdbuf();
      m.scene_text = text.str();
      m.overrides = a.overrides;
      m.frame_start = scene.shot.frame_start;
      m.frame_end = scene.shot.frame_end;
      write_run_manifest(scene.output.directory, m);
    }  // else run_shot reports the directory
  }
  std::unique_ptr<PreviewJob> preview;
  if (a.preview || scene.render.preview) {
    PreviewJobOptions po;
    po.outdir = scene.output.directory;
    po.first_frame = po.framing_frame = scene.shot.frame_start;
    po.last_frame = scene.shot.frame_end;
    po.threads = scene.shot.threads;
    po.log = [&](const std::string& m) { progress.message(m); };
    preview = std::make_unique<PreviewJob>(scene, po);
  }
  RunOptions ro;
  ro.resume = a.resume;
  ro.scene_fingerprint = ls.fingerprint;
  ro.on_substep = [&](int f, int s, double dt, double t, std::size_t n) {
    progress.substep(f, s, dt, t, n);
  };
  ro.on_frame = [&](const FrameStats& s) {
    if (s.frame < scene.shot.frame_start) return;
    progress.frame_done(s);
    if (preview && !preview->render_frame(s.frame)) progress.message("error: " + preview->errors().back());
  };
  ro.log = [&](const std::string& m) { progress.message(m); };
  ro.warn = [&](const std::string& m) { progress.warning(m); };
  const int n = run_shot(scene, ro);
  progress.finish();
  progress.message("wrote " + std::to_string(n) + " frames to " + scene.output.directory);
  if (preview) {
    const int failed = preview->finish();
    progress.message("previews: " + preview->image_path(scene.shot.frame_start) + " ... (" +
                     format_seconds(preview->seconds()) + " rendering)");
    if (failed > 0) {
      std::fprintf(stderr, "error: %d preview frame(s) failed\n", failed);
      return kExitSimulation;
    }
  }
  return kExitOk;
}

}  // namespace shellmpm

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "app/commands.h"
#include "app/frame_range.h"
#include "app/scene_loading.h"
#include "app/stop_signals.h"
#include "io/atomic_file.h"
#include "render/preview_job.h"
#include "render/run_manifest.h"
#include "shot/run_resolved.h"
#include "shot/shot_runner.h"
#include "sim/core/parallel.h"
#include "sim/scene/scene_words.h"

namespace shellmpm {

namespace {

/// run.json, which lets `shellmpm render OUTDIR` find the scene later (when the output
/// folder cannot be made, run_shot reports it), with a "resolved" block beside the
/// manifest's fields for tools that do not read YAML (shot/run_resolved.h; the Blender
/// loader in tools/blender).
void write_manifest(const RunArgs& a, const Scene& scene) {
  std::error_code ec;
  std::filesystem::create_directories(scene.output.directory, ec);
  if (!std::filesystem::is_directory(scene.output.directory, ec)) return;
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
  // The resolved block is added to the file the manifest writer made (its fields stay
  // exactly as render/run_manifest.cpp writes and reads them).
  const std::string path = run_manifest_path(scene.output.directory);
  std::ifstream written(path, std::ios::binary);
  std::stringstream manifest;
  manifest << written.rdbuf();
  nlohmann::json j = nlohmann::json::parse(manifest.str());
  j["resolved"] = resolved_run_settings(scene);
  write_text_atomic(path, j.dump(2) + "\n");
}

/// The preview renderer of `run --preview` (render.preview), drawing each frame once written.
std::unique_ptr<PreviewJob> make_preview(const Scene& scene, Progress& progress) {
  PreviewJobOptions po;
  po.outdir = scene.output.directory;
  po.first_frame = po.framing_frame = scene.shot.frame_start;
  po.last_frame = scene.shot.frame_end;
  po.threads = scene.shot.threads;
  po.log = [&progress](const std::string& m) { progress.message(m); };
  return std::make_unique<PreviewJob>(scene, po);
}

}  // namespace

int run_command(const RunArgs& a) {
  if (!a.frames.empty()) parse_frames_flag(a.frames);  // before the scene: numbers of any length
  LoadedScene ls = load_scene_for_cli(a, a.frames, a.output);
  const Scene& scene = ls.scene;
  prepare_run(ls, a.force, a.preview || scene.render.preview);
  ThreadLimit limit(scene.shot.threads);
  Progress progress(a.verbosity, scene.shot.frame_start, scene.shot.frame_end);
  if (a.verbosity == Verbosity::Verbose)
    progress.message("threads: " + std::to_string(ThreadLimit::active()));
  if (!scene.shot.integrator_reason.empty())
    progress.message("integrator: auto chose " + word_of(scene.shot.integrator) + ": " +
                     scene.shot.integrator_reason);
  if (scene.shot.shell_fields_in_solve && scene.shot.integrator == Integrator::Implicit)
    progress.warning(kFieldsInSolveWarning);
  write_manifest(a, scene);
  std::unique_ptr<PreviewJob> preview;
  if (a.preview || scene.render.preview) preview = make_preview(scene, progress);
  StopSignals signals;
  bool stop_noted = false;
  auto note_stop = [&](int frame) {
    if (stop_noted || StopSignals::pending() == 0) return;
    stop_noted = true;
    progress.warning(StopSignals::name(StopSignals::pending()) + ": stopping after frame " +
                     std::to_string(frame) +
                     " (a checkpoint follows); send it again to stop at once");
  };
  RunOptions ro;
  ro.resume = a.resume;
  ro.scene_fingerprint = ls.fingerprint;
  ro.stop_requested = [] { return StopSignals::pending(); };
  ro.on_substep = [&](int f, int s, double dt, double t, std::size_t n) {
    note_stop(f);
    progress.substep(f, s, dt, t, n);
  };
  ro.on_frame = [&](const FrameStats& s) {
    if (s.frame < scene.shot.frame_start) return;
    progress.frame_done(s);
    if (preview && !preview->render_frame(s.frame))
      progress.message("error: " + preview->errors().back());
  };
  ro.log = [&](const std::string& m) { progress.message(m); };
  ro.warn = [&](const std::string& m) { progress.warning(m); };
  const RunResult result = run_shot(scene, ro);
  progress.finish();
  if (result.stopped_by != 0) {
    // Printed even with --quiet: the job did not finish.
    std::fprintf(stderr,
                 "stopped by %s after frame %d (%d frames written to %s); checkpoint '%s' "
                 "written: run the same command with --resume to continue\n",
                 StopSignals::name(result.stopped_by).c_str(), result.last_frame,
                 result.frames_written, scene.output.directory.c_str(), result.checkpoint.c_str());
    return 128 + result.stopped_by;
  }
  progress.message("wrote " + std::to_string(result.frames_written) + " frames to " +
                   scene.output.directory);
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

// `shellmpm render OUTDIR`: preview images of a run's caches (render/preview_job).
#include <chrono>
#include <cstdio>
#include <regex>

#include "app/commands.h"
#include "app/frame_range.h"
#include "io/output_folders.h"
#include "io/scene_reader.h"
#include "io/user_error.h"
#include "render/preview_job.h"
#include "render/run_manifest.h"
#include "sim/core/parallel.h"
#include "sim/scene/scene_words.h"

namespace shellmpm {

namespace {

void parse_frames(const std::string& text, int& a, int& b) {
  const FrameRange r = parse_frames_flag(text);
  a = r.first;
  b = r.last;
}

void parse_size(const std::string& text, int& w, int& h) {
  std::smatch m;
  const std::regex re(R"((\d{1,5})x(\d{1,5}))");
  if (!std::regex_match(text, m, re))
    throw UserError("--size " + text, 0, "", "expected WxH in pixels, e.g. 1280x720");
  w = std::stoi(m[1]);
  h = std::stoi(m[2]);
  if (w < 16 || h < 16 || w > 8192 || h > 8192)
    throw UserError("--size " + text, 0, "", "width and height must be in [16, 8192]");
}

}  // namespace

int render_command(const RenderArgs& a) {
  Scene scene;
  int framing = 1;
  if (!a.scene.empty()) {
    scene = read_scene(a.scene, a.overrides);
    scene.output.directory = a.outdir;
  } else {
    const RunManifest m = read_run_manifest(a.outdir);
    scene = scene_from_manifest(m, a.outdir, a.overrides);
  }
  framing = scene.shot.frame_start;
  int first = scene.shot.frame_start, last = scene.shot.frame_end;
  if (!a.frames.empty()) parse_frames(a.frames, first, last);
  RenderSettings& rs = scene.render;
  if (!a.size.empty()) parse_size(a.size, rs.width, rs.height);
  if (!a.renderer.empty())
    rs.renderer = *enum_of_word<RendererKind>(a.renderer);  // CLI checked the word
  if (!a.camera.empty()) {
    std::string names = "auto";
    bool known = a.camera == "auto";
    for (const RenderCamera& c : rs.cameras) {
      names += ", " + c.name;
      known = known || c.name == a.camera;
    }
    if (!known)
      throw UserError("--camera " + a.camera, 0, "", "unknown camera (cameras: " + names + ")");
    rs.camera = a.camera;
  }
  const int threads = a.threads >= 0 ? a.threads : scene.shot.threads;
  ThreadLimit limit(threads);
  const bool quiet = a.verbosity == Verbosity::Quiet;
  auto say = [&](const std::string& m) {
    if (!quiet) std::fprintf(stderr, "%s\n", m.c_str());
  };
  create_output_folders(scene, /*previews=*/true);  // render.pattern may name a sub-folder
  PreviewJobOptions po;
  po.outdir = a.outdir;
  po.first_frame = first;
  po.last_frame = last;
  po.framing_frame = framing;
  po.threads = threads;
  po.log = say;
  PreviewJob job(scene, po);
  if (a.verbosity == Verbosity::Verbose)
    say("renderer " + word_of(rs.renderer) + ", " + std::to_string(rs.width) + "x" +
        std::to_string(rs.height) + ", threads " + std::to_string(ThreadLimit::active()));
  for (int f = first; f <= last; ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    if (job.render_frame(f)) {
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      char line[64];
      std::snprintf(line, sizeof line, " (%.2f s)", s);
      say("frame " + std::to_string(f) + ": " + job.image_path(f) + line);
    } else {
      std::fprintf(stderr, "error: %s\n", job.errors().back().c_str());
    }
  }
  const int failed = job.finish();
  if (failed > 0) {
    std::fprintf(stderr, "error: %d of %d frames could not be rendered:\n", failed,
                 last - first + 1);
    for (const std::string& e : job.errors()) std::fprintf(stderr, "  %s\n", e.c_str());
    return kExitSimulation;
  }
  return kExitOk;
}

}  // namespace shellmpm

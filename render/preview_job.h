// Rendering a run's frames to preview.####.png, then a contact sheet and an MP4: what
// `shellmpm render` does after a run and `shellmpm run --preview` does while it runs.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "render/image.h"
#include "render/renderer.h"
#include "render/scene_assembler.h"
#include "sim/scene/scene.h"

namespace shellmpm {

struct PreviewJobOptions {
  std::string outdir;   ///< where the caches are and the previews go
  int first_frame = 1;  ///< the frames that will be rendered, in order
  int last_frame = 1;
  int framing_frame = 1;  ///< the frame the automatic camera frames (see SceneAssembler)
  int threads = 0;        ///< llvmpipe / Embree threads (0 = all cores); TBB: the caller
  std::function<void(const std::string&)> log;  ///< progress and notes
};

class PreviewJob {
 public:
  /// Creates the renderer (GL context or Embree device) once, for all frames.
  /// `scene.render` holds the settings (command-line choices already applied).
  PreviewJob(const Scene& scene, PreviewJobOptions options);
  ~PreviewJob();

  /// Renders `frame` and writes its PNG. A missing or corrupt cache file is recorded in
  /// errors() (naming the file) and false returned; the job goes on with other frames.
  /// @throws UserError for settings that cannot work (the first call builds the scene
  ///         assembler), std::runtime_error / std::system_error for renderer or write failures.
  bool render_frame(int frame);

  /// Writes the contact sheet (frames rendered so far) and, when ffmpeg is on the PATH and
  /// every frame rendered, the MP4. Returns the number of frames that failed.
  int finish();

  const std::vector<std::string>& errors() const { return errors_; }
  /// The path of frame `frame`'s image.
  std::string image_path(int frame) const;
  /// Seconds spent in render_frame (reading caches, rendering, writing), summed.
  double seconds() const { return seconds_; }

 private:
  const Scene& scene_;
  PreviewJobOptions opt_;
  std::unique_ptr<Renderer> renderer_;
  std::unique_ptr<SceneAssembler> assembler_;
  std::vector<int> sheet_frames_;
  std::vector<Image> sheet_tiles_;
  std::vector<std::string> sheet_labels_;
  std::vector<std::string> errors_;
  int rendered_ = 0;
  double seconds_ = 0.0;

  void log(const std::string& m) const {
    if (opt_.log) opt_.log(m);
  }
  void write_movie();
};

/// The ffmpeg executable on the PATH, or "" when there is none.
std::string find_ffmpeg();

}  // namespace shellmpm

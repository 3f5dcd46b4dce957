#include "render/preview_job.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "io/atomic_file.h"

extern char** environ;

namespace shellmpm {
namespace {

namespace fs = std::filesystem;
constexpr int kSheetTiles = 24;
constexpr int kSheetTileWidth = 320;

/// "preview.####.png" -> "preview.%04d.png" (ffmpeg's sequence syntax).
std::string printf_pattern(const std::string& pattern) {
  const auto a = pattern.find('#');
  const auto b = pattern.find_first_not_of('#', a);
  const std::size_t n = (b == std::string::npos ? pattern.size() : b) - a;
  std::string escaped;
  for (char c : pattern.substr(0, a)) escaped += c == '%' ? std::string("%%") : std::string(1, c);
  std::string tail;
  for (char c : pattern.substr(a + n)) tail += c == '%' ? std::string("%%") : std::string(1, c);
  return escaped + "%0" + std::to_string(n) + "d" + tail;
}

}  // namespace

std::string find_ffmpeg() {
  const char* path = std::getenv("PATH");
  if (!path) return "";
  std::stringstream ss(path);
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    if (dir.empty()) continue;
    const std::string f = dir + "/ffmpeg";
    if (::access(f.c_str(), X_OK) == 0) return f;
  }
  return "";
}

PreviewJob::PreviewJob(const Scene& scene, PreviewJobOptions options)
    : scene_(scene), opt_(std::move(options)) {
  renderer_ = make_renderer(scene_.render.renderer, opt_.threads);
  const int n = opt_.last_frame - opt_.first_frame + 1;
  for (int i = 0; i < std::min(n, kSheetTiles); ++i) {
    const int f = n <= kSheetTiles ? opt_.first_frame + i
                                   : opt_.first_frame +
                                         static_cast<int>(std::lround(static_cast<double>(i) *
                                                                      (n - 1) / (kSheetTiles - 1)));
    sheet_frames_.push_back(f);
  }
}

PreviewJob::~PreviewJob() = default;

std::string PreviewJob::image_path(int frame) const {
  return frame_path(opt_.outdir, scene_.render.pattern, frame);
}

bool PreviewJob::render_frame(int frame) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!assembler_)
    assembler_ = std::make_unique<SceneAssembler>(scene_, opt_.outdir, opt_.framing_frame);
  PreviewScene ps;
  try {
    ps = assembler_->assemble(frame);
  } catch (const CacheError& e) {
    errors_.push_back(std::string("frame ") + std::to_string(frame) + ": " + e.what());
    return false;
  }
  const Image im = renderer_->render(ps, assembler_->camera());
  write_png(image_path(frame), im);
  ++rendered_;
  if (std::find(sheet_frames_.begin(), sheet_frames_.end(), frame) != sheet_frames_.end()) {
    sheet_tiles_.push_back(downscale(im, kSheetTileWidth));
    sheet_labels_.push_back(std::to_string(frame));
  }
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return true;
}

int PreviewJob::finish() {
  const RenderSettings& rs = scene_.render;
  if (rs.contact_sheet && !sheet_tiles_.empty()) {
    const int columns = sheet_tiles_.size() <= 4    ? static_cast<int>(sheet_tiles_.size())
                        : sheet_tiles_.size() <= 9  ? 3
                        : sheet_tiles_.size() <= 16 ? 4
                                                    : 6;
    const std::string path = opt_.outdir + "/contact_sheet.png";
    write_png(path, contact_sheet(sheet_tiles_, sheet_labels_, columns));
    log("wrote " + path + " (" + std::to_string(sheet_tiles_.size()) + " frames)");
  }
  if (rs.movie) write_movie();
  return static_cast<int>(errors_.size());
}

void PreviewJob::write_movie() {
  if (rendered_ < 2) return;
  if (!errors_.empty()) {
    log("preview.mp4 skipped: some frames failed to render");
    return;
  }
  const std::string ffmpeg = find_ffmpeg();
  if (ffmpeg.empty()) {
    log("preview.mp4 skipped: ffmpeg is not installed (Debian: apt-get install ffmpeg)");
    return;
  }
  const std::string target = opt_.outdir + "/preview.mp4";
  std::ostringstream fps;
  fps << scene_.shot.fps;
  const std::string tmp = target + ".tmp." + std::to_string(::getpid()) + ".mp4";
  std::vector<std::string> args = {ffmpeg,
                                   "-y",
                                   "-nostdin",
                                   "-loglevel",
                                   "error",
                                   "-framerate",
                                   fps.str(),
                                   "-start_number",
                                   std::to_string(opt_.first_frame),
                                   "-i",
                                   opt_.outdir + "/" + printf_pattern(scene_.render.pattern),
                                   "-frames:v",
                                   std::to_string(rendered_),
                                   "-vf",
                                   "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                   "-c:v",
                                   "libx264",
                                   "-pix_fmt",
                                   "yuv420p",
                                   "-crf",
                                   "18"};
  if (opt_.threads > 0) {
    args.push_back("-threads");
    args.push_back(std::to_string(opt_.threads));
  }
  args.push_back("-f");
  args.push_back("mp4");
  args.push_back(tmp);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  int status = 0;
  if (posix_spawn(&pid, ffmpeg.c_str(), nullptr, nullptr, argv.data(), environ) != 0 ||
      waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::error_code ec;
    fs::remove(tmp, ec);
    log("preview.mp4 not written: ffmpeg failed (see its message above)");
    return;
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    log("preview.mp4 not written: cannot rename " + tmp + ": " + ec.message());
    return;
  }
  log("wrote " + target);
}

}  // namespace shellmpm

// The MP4 branch of the preview job (render/preview_job.cpp, write_movie): with ffmpeg on
// the PATH `run --preview` writes preview.mp4, a real MP4 with one video frame per
// preview frame at the (even-padded) preview size; without ffmpeg, or when ffmpeg fails,
// the movie is skipped with a message and the run still succeeds.
#include <catch2/catch.hpp>
#include <filesystem>
#include <string>

#include "render/preview_job.h"
#include "tests/app/cli_harness.h"

using namespace shellmpm_test;
namespace fs = std::filesystem;

namespace {

// Four frames of a small elastic box; an odd preview size so that ffmpeg's pad to even
// dimensions (yuv420p) is exercised: 65x49 -> 66x50.
const std::string kScene = tiny_jelly_scene(4, "out/never_used", "render:\n  size: [65, 49]\n");

/// The value of `key=` in ffprobe's "default" output, or "" when absent.
std::string probe_value(const std::string& probe, const std::string& key) {
  const std::string k = key + "=";
  std::size_t at = 0;
  while ((at = probe.find(k, at)) != std::string::npos) {
    if (at == 0 || probe[at - 1] == '\n') {
      const std::size_t end = probe.find('\n', at);
      return probe.substr(at + k.size(),
                          end == std::string::npos ? std::string::npos : end - at - k.size());
    }
    at += k.size();
  }
  return "";
}

}  // namespace

TEST_CASE("preview movie: run --preview writes preview.mp4 that ffprobe reads back",
          "[render][cli]") {
  INFO("ffmpeg (with ffprobe) is needed for this test: sh tools/install-deps.sh");
  REQUIRE_FALSE(shellmpm::find_ffmpeg().empty());
  REQUIRE(run_command("ffprobe -version").code == 0);

  TempDir d("preview_movie");
  const std::string scene = d.write("scene.yaml", kScene);
  const std::string out = d.file("out");
  const CmdResult r = run_shellmpm("run " + scene + " --preview --threads 2 -o " + out);
  INFO(r.output);
  REQUIRE(r.code == 0);
  const std::string mp4 = out + "/preview.mp4";
  CHECK(r.output.find("wrote " + mp4) != std::string::npos);
  REQUIRE(fs::exists(mp4));
  CHECK(d.temp_files() == 0);

  // An ISO base media file: the first box is 'ftyp' (bytes 4-7).
  const std::string bytes = read_text(mp4);
  REQUIRE(bytes.size() > 8);
  CHECK(bytes.substr(4, 4) == "ftyp");

  // One H.264 frame per preview frame, at the preview size padded to even.
  const CmdResult probe = run_command(
      "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
      "stream=codec_name,width,height,nb_read_frames -of default=noprint_wrappers=1 " +
      mp4);
  INFO(probe.output);
  REQUIRE(probe.code == 0);
  CHECK(probe_value(probe.output, "codec_name") == "h264");
  CHECK(probe_value(probe.output, "width") == "66");
  CHECK(probe_value(probe.output, "height") == "50");
  CHECK(probe_value(probe.output, "nb_read_frames") == "4");
}

TEST_CASE(
    "preview movie: without ffmpeg, or when ffmpeg fails, preview.mp4 is skipped and the job "
    "succeeds",
    "[render][cli]") {
  TempDir d("preview_movie_skip");
  const std::string scene = d.write("scene.yaml", kScene);
  const std::string out = d.file("out");
  // No ffmpeg on the PATH (the binary and /bin/sh are named by absolute paths).
  const std::string nowhere = "PATH=" + d.file("empty_bin");
  fs::create_directories(d.file("empty_bin"));
  const CmdResult r = run_shellmpm("run " + scene + " --preview --threads 2 -o " + out, nowhere);
  INFO(r.output);
  CHECK(r.code == 0);
  CHECK(r.output.find("preview.mp4 skipped: ffmpeg is not installed") != std::string::npos);
  for (int f = 1; f <= 4; ++f) CHECK(fs::exists(out + "/preview.000" + std::to_string(f) + ".png"));
  CHECK(fs::exists(out + "/contact_sheet.png"));
  CHECK_FALSE(fs::exists(out + "/preview.mp4"));

  // `render` of the same run, same PATH: the same note, exit 0.
  const CmdResult again = run_shellmpm("render " + out + " --threads 2", nowhere);
  INFO(again.output);
  CHECK(again.code == 0);
  CHECK(again.output.find("preview.mp4 skipped: ffmpeg is not installed") != std::string::npos);
  CHECK_FALSE(fs::exists(out + "/preview.mp4"));

  // An ffmpeg that writes part of its output file and fails: the partial temporary is
  // removed, no preview.mp4, a note, and the job still succeeds.
  fs::create_directories(d.file("bad_bin"));
  const std::string fake = d.write("bad_bin/ffmpeg",
                                   "#!/bin/sh\n"
                                   "for a in \"$@\"; do last=\"$a\"; done\n"
                                   "printf 'half a movie' > \"$last\"\n"
                                   "echo 'fake ffmpeg: encoder exploded' >&2\n"
                                   "exit 1\n");
  fs::permissions(fake, fs::perms::owner_all);
  const CmdResult failed =
      run_shellmpm("render " + out + " --threads 2", "PATH=" + d.file("bad_bin"));
  INFO(failed.output);
  CHECK(failed.code == 0);
  CHECK(failed.output.find("fake ffmpeg: encoder exploded") != std::string::npos);
  CHECK(failed.output.find("preview.mp4 not written: ffmpeg failed") != std::string::npos);
  CHECK_FALSE(fs::exists(out + "/preview.mp4"));
  CHECK(d.temp_files() == 0);
}

#include "app/progress.h"

#include <unistd.h>

#include <cstdio>

namespace shellmpm {

std::string format_seconds(double s) {
  const long t = static_cast<long>(s + 0.5);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%02ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  return buf;
}

Progress::Progress(Verbosity v, int first_frame, int last_frame)
    : verbosity_(v), tty_(isatty(fileno(stderr)) != 0), first_(first_frame), last_(last_frame) {
  start_ = last_draw_ = std::chrono::steady_clock::now();
}

std::string Progress::eta(int frame) const {
  const double el =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const int done = frame - first_;
  if (done <= 0) return "--:--:--";
  return format_seconds(el / done * (last_ - frame + 1));
}

void Progress::substep(int frame, int sub, double dt, double, std::size_t particles) {
  if (verbosity_ == Verbosity::Quiet || !tty_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(200)) return;
  last_draw_ = now;
  const double el = std::chrono::duration<double>(now - start_).count();
  std::fprintf(stderr,
               "\r\033[Kframe %d/%d  substep %d  dt %.3g s  particles %zu  elapsed %s  ETA %s",
               frame, last_, sub, dt, particles, format_seconds(el).c_str(), eta(frame).c_str());
  std::fflush(stderr);
  line_open_ = true;
}

void Progress::frame_done(const FrameStats& s) {
  if (verbosity_ == Verbosity::Quiet) return;
  if (line_open_) std::fputs("\r\033[K", stderr);
  line_open_ = false;
  const double el =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(
      stderr,
      "frame %d/%d  substeps %d  dt %.3g..%.3g s  particles %zu  %.2f s  elapsed %s  ETA %s\n",
      s.frame, last_, s.substeps, s.dt_min, s.dt_max, s.particles, s.wall_seconds,
      format_seconds(el).c_str(), eta(s.frame + 1).c_str());
  if (verbosity_ == Verbosity::Verbose) {
    std::string line = "  stages:";
    for (const auto& [name, sec] : s.stage_seconds) {
      char buf[64];
      std::snprintf(buf, sizeof buf, " %s %.3f s", name.c_str(), sec);
      line += buf;
    }
    std::fprintf(stderr, "%s\n  kinetic %.6g J  elastic %.6g J  max speed %.4g m/s\n", line.c_str(),
                 s.kinetic_energy, s.elastic_energy, s.max_speed);
  }
}

void Progress::message(const std::string& m) {
  if (verbosity_ == Verbosity::Quiet) return;
  if (line_open_) std::fputs("\r\033[K", stderr);
  line_open_ = false;
  std::fprintf(stderr, "%s\n", m.c_str());
}

void Progress::warning(const std::string& m) {
  if (line_open_) std::fputs("\r\033[K", stderr);
  line_open_ = false;
  std::fprintf(stderr, "warning: %s\n", m.c_str());
}

void Progress::finish() {
  if (line_open_) std::fputs("\n", stderr);
  line_open_ = false;
}

void print_line(const std::string& m) {
  std::printf("%s\n", m.c_str());
  std::fflush(stdout);
}

}  // namespace shellmpm

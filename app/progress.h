// Progress reporting for `shellmpm run`: a live status line on a terminal, one log
// line per frame otherwise.
#pragma once
#include <chrono>
#include <cstddef>
#include <string>

#include "sim/solver/frame_stats.h"

namespace shellmpm {

enum class Verbosity { Quiet, Normal, Verbose };

/// One line on stdout, flushed at once (the study's and converge's progress, which may be
/// piped to a log while the runs take minutes).
void print_line(const std::string& m);

class Progress {
 public:
  Progress(Verbosity v, int first_frame, int last_frame);
  void substep(int frame, int sub, double dt, double t, std::size_t particles);
  void frame_done(const FrameStats& s);
  void message(const std::string& m);
  /// "warning: m" on stderr, even with --quiet.
  void warning(const std::string& m);
  void finish();

 private:
  std::string eta(int frame) const;
  Verbosity verbosity_;
  bool tty_;
  int first_, last_;
  std::chrono::steady_clock::time_point start_, last_draw_;
  bool line_open_ = false;
};

std::string format_seconds(double s);

}  // namespace shellmpm

// SIGTERM and SIGINT as a request to stop: farm schedulers send SIGTERM (and SIGKILL a
// while later), a user presses Ctrl-C. The first one only sets a flag (all a signal
// handler may safely do); the run polls it, finishes the frame it is computing, writes a
// checkpoint and exits 128 + the signal number (143, 130). The handler is installed
// with SA_RESETHAND, so a second signal kills at once, as it did before.
#pragma once
#include <string>

namespace shellmpm {

/// Installs the handlers for its lifetime (one instance at a time) and restores the
/// previous ones when destroyed.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// The number of the first signal received since construction, or 0.
  static int pending();
  /// "SIGTERM", "SIGINT" (or "signal N").
  static std::string name(int signal);
};

}  // namespace shellmpm

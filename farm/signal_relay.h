// Passing SIGTERM and SIGINT on to child processes: `batch task` to its `shellmpm run`,
// the local engine to its running tasks. Each signal received is sent to every registered
// child once (so a second signal still stops a run at once, as it does without the farm),
// and remembered so the caller stops starting new work.
#pragma once
#include <sys/types.h>

namespace shellmpm {

class SignalRelay {
 public:
  /// The most children relayed to at once.
  static constexpr int kMaxChildren = 256;
  SignalRelay();   ///< installs the handlers (SIGTERM, SIGINT)
  ~SignalRelay();  ///< restores the previous ones
  SignalRelay(const SignalRelay&) = delete;
  SignalRelay& operator=(const SignalRelay&) = delete;
  /// Registers a child (false when kMaxChildren are registered).
  bool add(pid_t pid);
  void remove(pid_t pid);
  /// The first signal received since construction, or 0.
  static int pending();
};

}  // namespace shellmpm

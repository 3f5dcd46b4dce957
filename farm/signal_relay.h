// Passing SIGTERM and SIGINT on to child processes, and remembering that one came so the
// caller starts no new work.
//
// The local engine (`batch run`) passes every signal on to its tasks, which run in process
// groups of their own. `batch task` passes only the first one on to its `shellmpm run`, as
// the other of the two signals (TERM as INT, INT as TERM): the run shares the task's
// process group, so a scheduler that signals the whole process tree (Slurm's job kill, a
// terminal's Ctrl-C) reaches it directly too, and the run, which stops at once on a second
// signal of one kind, takes the direct and the passed-on one as a single request to stop
// after its frame with a checkpoint (exit 143 or 130, whichever came first).
#pragma once
#include <sys/types.h>

namespace shellmpm {

class SignalRelay {
 public:
  enum class Mode {
    Every,         ///< every signal to every child, as received
    FirstSwapped,  ///< the first signal only, TERM passed on as INT and INT as TERM
  };
  /// The most children relayed to at once.
  static constexpr int kMaxChildren = 256;
  explicit SignalRelay(Mode mode);  ///< installs the handlers (SIGTERM, SIGINT)
  ~SignalRelay();                   ///< restores the previous ones
  SignalRelay(const SignalRelay&) = delete;
  SignalRelay& operator=(const SignalRelay&) = delete;
  /// Registers a child (false when kMaxChildren are registered). A signal that came
  /// before is passed on to it now.
  bool add(pid_t pid);
  void remove(pid_t pid);
  /// The first signal received since construction, or 0.
  static int pending();
};

}  // namespace shellmpm

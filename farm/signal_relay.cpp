#include "farm/signal_relay.h"

#include <signal.h>

#include <csignal>

namespace shellmpm {
namespace {

// The global state a signal handler needs, owned by the one SignalRelay alive: the children
// (0: a free slot), the first signal received, the mode, whether it was passed on.
volatile std::sig_atomic_t g_children[SignalRelay::kMaxChildren] = {};
volatile std::sig_atomic_t g_pending = 0;
volatile std::sig_atomic_t g_first_only = 0;
volatile std::sig_atomic_t g_passed = 0;
struct sigaction g_old_term, g_old_int;

/// The signal to send the children for `sig`, or 0 for none.
int relayed(int sig) {
  if (!g_first_only) return sig;
  if (g_passed) return 0;
  return sig == SIGTERM ? SIGINT : sig == SIGINT ? SIGTERM : sig;
}

extern "C" void on_relay_signal(int sig) {
  if (g_pending == 0) g_pending = sig;
  const int out = relayed(sig);
  if (out == 0) return;
  bool any = false;
  for (int i = 0; i < SignalRelay::kMaxChildren; ++i) {
    if (g_children[i] > 0) {
      kill(static_cast<pid_t>(g_children[i]), out);
      any = true;
    }
  }
  if (any) g_passed = 1;
}

}  // namespace

SignalRelay::SignalRelay(Mode mode) {
  g_pending = 0;
  g_passed = 0;
  g_first_only = mode == Mode::FirstSwapped;
  for (int i = 0; i < kMaxChildren; ++i) g_children[i] = 0;
  struct sigaction sa = {};
  sa.sa_handler = on_relay_signal;
  sigemptyset(&sa.sa_mask);
  sigaddset(&sa.sa_mask, SIGTERM);  // one handler at a time
  sigaddset(&sa.sa_mask, SIGINT);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGTERM, &sa, &g_old_term);
  sigaction(SIGINT, &sa, &g_old_int);
}

SignalRelay::~SignalRelay() {
  sigaction(SIGTERM, &g_old_term, nullptr);
  sigaction(SIGINT, &g_old_int, nullptr);
}

bool SignalRelay::add(pid_t pid) {
  for (int i = 0; i < kMaxChildren; ++i) {
    if (g_children[i] == 0) {
      g_children[i] = pid;
      // A signal that came before the child was registered reaches it now.
      if (g_pending != 0) {
        const int out = relayed(g_pending);
        if (out != 0) kill(pid, out);
        if (g_first_only) g_passed = 1;
      }
      return true;
    }
  }
  return false;
}

void SignalRelay::remove(pid_t pid) {
  for (int i = 0; i < kMaxChildren; ++i)
    if (g_children[i] == pid) g_children[i] = 0;
}

int SignalRelay::pending() {
  return g_pending;
}

}  // namespace shellmpm

#include "farm/signal_relay.h"

#include <signal.h>

#include <csignal>

namespace shellmpm {
namespace {

// The global state a signal handler needs, owned by the one SignalRelay alive: the children
// (0: a free slot) and the first signal received.
volatile std::sig_atomic_t g_children[SignalRelay::kMaxChildren] = {};
volatile std::sig_atomic_t g_pending = 0;
struct sigaction g_old_term, g_old_int;

extern "C" void on_relay_signal(int sig) {
  if (g_pending == 0) g_pending = sig;
  for (int i = 0; i < SignalRelay::kMaxChildren; ++i)
    if (g_children[i] > 0) kill(static_cast<pid_t>(g_children[i]), sig);
}

}  // namespace

SignalRelay::SignalRelay() {
  g_pending = 0;
  for (int i = 0; i < kMaxChildren; ++i) g_children[i] = 0;
  struct sigaction sa = {};
  sa.sa_handler = on_relay_signal;
  sigemptyset(&sa.sa_mask);
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
      if (g_pending != 0) kill(pid, g_pending);
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

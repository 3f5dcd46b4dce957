#include "app/stop_signals.h"

#include <signal.h>

#include <csignal>

namespace shellmpm {
namespace {

// The one piece of global state a signal handler needs: written by the handler only.
volatile std::sig_atomic_t g_pending = 0;
struct sigaction g_old_term, g_old_int;

extern "C" void on_stop_signal(int signal) {
  if (g_pending == 0) g_pending = signal;
}

}  // namespace

StopSignals::StopSignals() {
  g_pending = 0;
  struct sigaction sa = {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  // SA_RESTART: a write interrupted by the signal goes on; SA_RESETHAND: the second
  // signal finds the default action and ends the process at once.
  sa.sa_flags = SA_RESTART | SA_RESETHAND;
  sigaction(SIGTERM, &sa, &g_old_term);
  sigaction(SIGINT, &sa, &g_old_int);
  // A signal the parent ignores (SIGINT for a job started with `nohup` or `&`) stays so.
  if (g_old_term.sa_handler == SIG_IGN) sigaction(SIGTERM, &g_old_term, nullptr);
  if (g_old_int.sa_handler == SIG_IGN) sigaction(SIGINT, &g_old_int, nullptr);
}

StopSignals::~StopSignals() {
  sigaction(SIGTERM, &g_old_term, nullptr);
  sigaction(SIGINT, &g_old_int, nullptr);
}

int StopSignals::pending() {
  return g_pending;
}

std::string StopSignals::name(int signal) {
  if (signal == SIGTERM) return "SIGTERM";
  if (signal == SIGINT) return "SIGINT";
  return "signal " + std::to_string(signal);
}

}  // namespace shellmpm

#include "scheduler/queue/stop.h"

namespace gravsweep::queue {

namespace {

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the stop flag is set from a signal handler");

extern "C" void on_stop_signal(int) { g_stop.store(true); }

struct sigaction stop_action() {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;
  return sa;
}

}  // namespace

std::atomic<bool>& stop_requested() { return g_stop; }

void install_stop_signals() {
  const struct sigaction sa = stop_action();
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

ScopedStopSignals::ScopedStopSignals() {
  g_stop.store(false);
  const struct sigaction sa = stop_action();
  sigaction(SIGINT, &sa, &old_int_);
  sigaction(SIGTERM, &sa, &old_term_);
}

ScopedStopSignals::~ScopedStopSignals() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

}  // namespace gravsweep::queue

// The one stop request of a gravsweep process: SIGINT and SIGTERM set it (once signals are
// installed), code may set it too (a worker whose supervisor is gone), and every long piece of work
// reads it (bed preparation and drops poll it between steps; workers between jobs; `status --watch`
// between refreshes). One flag and one handler for the whole process, so a verb and the work it
// runs can never disagree on whether a stop was asked for.
#pragma once
#include <atomic>
#include <csignal>

namespace gravsweep::queue {

/// The flag. Async-signal-safe to set (lock-free atomic).
std::atomic<bool>& stop_requested();

/// Installs the handler on SIGINT and SIGTERM for the rest of the process (workers, `status`).
void install_stop_signals();

/// Installs the handler for a scope and puts the previous handlers back after it (`run`, which a
/// test or a library caller may call more than once); the flag is cleared on entry.
class ScopedStopSignals {
 public:
  ScopedStopSignals();
  ~ScopedStopSignals();
  ScopedStopSignals(const ScopedStopSignals&) = delete;
  ScopedStopSignals& operator=(const ScopedStopSignals&) = delete;

 private:
  struct sigaction old_int_ {
  }, old_term_{};
};

}  // namespace gravsweep::queue

// The heartbeat thread of a worker's running job and the check for a vanished supervisor
// (worker_heartbeat.h).
#include "scheduler/queue/worker_heartbeat.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "scheduler/queue/stop.h"

namespace gravsweep::queue::detail {

/// True when this worker was started by a `work --workers N` supervisor that is gone.
bool supervisor_gone() {
  static const long supervisor = [] {
    const char* s = std::getenv("GRAVSWEEP_SUPERVISOR_PID");
    return s ? std::atol(s) : 0L;
  }();
  return supervisor > 0 && static_cast<long>(getppid()) != supervisor;
}

/// `db` is the heartbeat connection of this worker: used only by this thread while the job runs.
void heartbeat_loop(const WorkerOptions& o, const Claim& c, JobSignals& sig, double interval_s,
                    std::unique_ptr<db::Database>& db) {
  auto next = std::chrono::steady_clock::now();  // first beat at once: the job has started
  std::unique_lock lock(sig.m);
  while (!sig.finished) {
    if (supervisor_gone()) queue::stop_requested().store(true);
    if (queue::stop_requested().load()) sig.stop.store(true);
    if (std::chrono::steady_clock::now() >= next) {
      const std::string phase = sig.phase, detail = sig.detail;
      const double f = sig.fraction;
      lock.unlock();
      try {
        if (!db) db = std::make_unique<db::Database>(o.db_path.string());
        if (!heartbeat(*db, c, o.lease_s, f, phase, detail)) {
          sig.lease_lost.store(true);
          sig.stop.store(true);
          std::fprintf(stderr, "worker %d: lease on job %s lost (another worker took it); stopping it\n",
                       static_cast<int>(getpid()), c.job_id.c_str());
        }
      } catch (const std::exception& e) {
        // A lost connection (server restarted) is made again at the next beat; the lease is fenced,
        // so a beat after the lease expired is refused as lost.
        const auto* dbe = dynamic_cast<const db::DbError*>(&e);
        if (dbe && dbe->connection_lost()) db.reset();
        std::fprintf(stderr, "worker %d: heartbeat failed (will retry): %s\n", static_cast<int>(getpid()), e.what());
      }
      lock.lock();
      next = std::chrono::steady_clock::now() +
             std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(interval_s));
      if (sig.lease_lost.load()) return;
    }
    sig.cv.wait_for(lock, std::chrono::milliseconds(50), [&sig] { return sig.finished; });
  }
}

}  // namespace gravsweep::queue::detail

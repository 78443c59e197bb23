// The heartbeat thread of a worker's running job (worker.cpp): it renews the job's lease and
// records its progress, and tells the job to stop when the lease is lost, the worker is told to
// stop, or its `work --workers N` supervisor is gone. Not part of the queue's interface.
#pragma once
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>

#include "scheduler/queue/queue.h"
#include "scheduler/queue/worker.h"

namespace gravsweep::queue::detail {

/// True when this worker was started by a `work --workers N` supervisor that is gone.
bool supervisor_gone();

/// Shared between the job and its heartbeat thread.
struct JobSignals {
  std::mutex m;
  std::condition_variable cv;
  bool finished = false;
  std::string phase = "started", detail;
  double fraction = 0;
  std::atomic<bool> stop{false};  // tells the runner to end early
  std::atomic<bool> lease_lost{false};
  std::atomic<bool> progress_saved{false};  // the runner left state the next attempt continues from
};

/// `db` is the heartbeat connection of this worker: used only by this thread while the job runs.
void heartbeat_loop(const WorkerOptions& o, const Claim& c, JobSignals& sig, double interval_s,
                    std::unique_ptr<db::Database>& db);

}  // namespace gravsweep::queue::detail

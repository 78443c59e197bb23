// A worker process: claims jobs one at a time and runs them until none is left (or forever with
// `follow`). While a job runs, a heartbeat thread (its own SQLite connection) renews the lease and
// records progress; if the lease is lost the job is told to stop and its output is discarded.
// Outputs are written under tmp/, fsynced, renamed to their final name, checksummed, and recorded
// in the transaction that marks the job done. SIGINT/SIGTERM stop the current job and give its
// lease back (the attempt does not count against the retry budget).
#pragma once
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>

#include "scheduler/queue/queue.h"

namespace gravsweep::queue {

using ProgressFn = std::function<void(const std::string& phase, double fraction, const std::string& detail)>;

struct RunContext {
  const Claim& claim;
  std::filesystem::path output_tmp;         ///< the runner writes its output here (under tmp/)
  std::filesystem::path dependency_output;  ///< the output of the job this one depends on (absolute; a drop: its bed)
  int threads = 1;
  ProgressFn progress;
  const std::atomic<bool>* stop = nullptr;  ///< set when the job must end early
  std::filesystem::path bed_cache;          ///< bed jobs: shared prepared beds (empty: none)
  /// Drop and bed jobs: this job's checkpoint, <files>/checkpoints/<job>.ckpt.h5 (pipeline/job_checkpoint.h),
  /// written every checkpoint_interval_s of wall time (<= 0: never) and on a stop request.
  std::filesystem::path checkpoint;
  double checkpoint_interval_s = 0;
  /// Set by a runner that saved state a later attempt continues from (a checkpoint beyond
  /// where this attempt started): a release of such an attempt does not count as a stall.
  std::atomic<bool>* progress_saved = nullptr;
  /// `work --max-memory`: a job whose scenario needs more (its estimate) is refused, permanently,
  /// before it allocates; 0: no limit.
  double max_memory_bytes = 0;
};

/// Runs one job; throws on failure (gravsweep::ConfigError, NumericalFailure and std::bad_alloc
/// are permanent: the job goes dead at once; anything else is retried with backoff).
using Runner = std::function<RunOutput(const RunContext&)>;
using RunnerTable = std::map<JobKind, Runner>;

struct WorkerOptions {
  std::filesystem::path db_path;  ///< an SQLite file or a postgresql:// URL
  std::filesystem::path files;    ///< the files root (empty: beside the SQLite file)
  int threads = 1;
  /// Threads all the workers of this campaign hold together (workers x threads): a bed job that
  /// runs alone gets them all (threads_for_claim). At most `threads` when there is one worker.
  int pool_threads = 1;
  double lease_s = 60;
  double heartbeat_s = 0;  ///< 0: min(lease / 4, 2 s)
  bool follow = false;     ///< keep waiting for new jobs when none is left
  double poll_s = 0.5;     ///< idle wait between claims when nothing is runnable
  long max_jobs = -1;      ///< stop after this many jobs (-1: no limit)
  double backoff_base_s = 2.0;
  int max_releases = kDefaultMaxReleases;  ///< a job interrupted this many times is stopped (dead)
  /// How long a worker keeps reconnecting to a PostgreSQL server that restarted or went away,
  /// with backoff, before it gives up (its running job goes on meanwhile; its lease is fenced).
  double db_outage_s = 300;
  /// Free space the files root must keep beyond the largest output seen (`work --min-free-mb`): below
  /// it the worker claims nothing (the disk is full), and a failed attempt is not counted.
  std::int64_t min_free_bytes = 64ll << 20;
  std::string code_version = "unknown";
  bool verbose = true;
  std::filesystem::path bed_cache;     ///< `work --bed-cache`: passed to the runners (RunContext)
  double checkpoint_interval_s = 300;  ///< `work --checkpoint-interval`: passed to the runners (RunContext)
  double max_memory_bytes = 0;         ///< `work --max-memory`: passed to the runners (RunContext)
};

struct WorkerReport {
  long done = 0, failed = 0, dead = 0, released = 0, fenced_out = 0, reclaimed = 0;
  bool interrupted = false;
  std::string disk_full;  ///< why the worker stopped claiming: the files root's disk is full (empty: it is not)
};

WorkerReport run_worker(const WorkerOptions& o, const RunnerTable& runners);

/// Writes `text` to `path` and fsyncs it (helper for runners); throws std::runtime_error naming the
/// file and the errno text (ENOSPC, EMFILE, EIO) when open, write, fsync or close fails.
void write_file_synced(const std::filesystem::path& path, const std::string& text);
/// fsync of a file or directory (best effort on directories).
void fsync_path(const std::filesystem::path& path);

}  // namespace gravsweep::queue

#include "scheduler/queue/worker.h"

#include <fcntl.h>
#include <sys/statvfs.h>
#include <fmt/format.h>

#include <new>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <thread>

#include "engine/core/error.h"
#include "scheduler/queue/stop.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/exit_codes.h"
#include "scheduler/queue/canonical.h"
#include "scheduler/queue/queue_internal.h"
#include "scheduler/queue/worker_heartbeat.h"

namespace gravsweep::queue {

namespace {

void sleep_interruptible(double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!queue::stop_requested().load() && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

/// The worker's connection, made again when a PostgreSQL server restarts or is away for a while: a
/// call that fails because the connection is gone is run again on a new connection, reconnecting
/// with backoff (0.2 s doubling to 5 s) for up to `outage_s`; then the error stands. Every call
/// re-prepares its statements, so none outlives the connection it was made on.
class Reconnecting {
 public:
  Reconnecting(db::Database& db, std::string location, double outage_s)
      : db_(db), location_(std::move(location)), outage_s_(outage_s) {}
  template <class Fn>
  auto operator()(Fn&& fn) {
    const auto give_up =
        std::chrono::steady_clock::now() +
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(outage_s_));
    double wait_s = 0.2;
    for (;;) {
      try {
        return fn();
      } catch (const db::DbError& e) {
        if (!e.connection_lost()) throw;
        reconnect(e, give_up, wait_s);
      }
    }
  }

 private:
  db::Database& db_;
  std::string location_;
  double outage_s_;

  void reconnect(const db::DbError& lost, std::chrono::steady_clock::time_point give_up, double& wait_s) {
    std::fprintf(stderr, "worker %d: database connection lost (%s); reconnecting for up to %.0f s\n",
                 static_cast<int>(getpid()), lost.what(), outage_s_);
    for (;;) {
      if (std::chrono::steady_clock::now() >= give_up || queue::stop_requested().load()) throw lost;
      sleep_interruptible(wait_s);
      wait_s = std::min(2 * wait_s, 5.0);
      try {
        db_ = db::Database(location_);
        std::fprintf(stderr, "worker %d: reconnected to the database\n", static_cast<int>(getpid()));
        return;
      } catch (const db::DbError& e) {
        if (!e.connection_lost()) throw;
      }
    }
  }
};

/// True when the job is done with the output of this attempt: a completion whose commit was
/// acknowledged by nobody (the connection broke) but went through.
bool completed_already(db::Database& db, const Claim& c) {
  db::Statement st(db, "SELECT count(*) FROM jobs WHERE job_id=? AND state='done' AND output_path=?");
  st.bind(1, c.job_id).bind(2, c.output_rel);
  st.step();
  return st.get_int(0) > 0;
}

/// Free bytes of the filesystem holding `dir` for an unprivileged writer; -1 when unknown.
std::int64_t free_bytes(const fs::path& dir) {
  struct statvfs st {};
  if (::statvfs(dir.c_str(), &st) != 0) return -1;
  return static_cast<std::int64_t>(st.f_bavail) * static_cast<std::int64_t>(st.f_frsize);
}

/// Empty while the files root has room for the next output (`min_free` plus the largest output
/// seen); otherwise why not.
std::string disk_full(const CampaignPaths& paths, std::int64_t min_free, std::int64_t largest_output) {
  const std::int64_t free = free_bytes(paths.root), need = min_free + largest_output;
  if (free < 0 || free >= need) return {};
  return fmt::format(
      "files root '{}': disk is full: {} bytes free, {} needed ({} kept free + {}, the largest output so far); "
      "jobs stay queued, nothing counted against them: free space (or lower --min-free-mb) and run work again",
      paths.root.string(), free, need, min_free, largest_output);
}

/// The largest output of a done job: what the next output is expected to need.
std::int64_t largest_output(db::Database& db) {
  db::Statement st(db, "SELECT coalesce(max(output_bytes), 0) FROM jobs WHERE state='done'");
  st.step();
  return st.get_int(0);
}

/// True when a failed attempt failed because of its environment, not of the job: the disk of the
/// files root is full now, or the error says so.
bool environmental(const std::string& error, const std::string& full) {
  return !full.empty() || error.find(std::strerror(ENOSPC)) != std::string::npos ||
         error.find("disk is full") != std::string::npos;
}

void remove_tmp_of(const fs::path& tmp_dir, const std::string& prefix) {
  std::error_code ec;
  if (!fs::exists(tmp_dir, ec)) return;
  for (const auto& e : fs::directory_iterator(tmp_dir, ec))
    if (e.path().filename().string().rfind(prefix, 0) == 0) fs::remove_all(e.path(), ec);
}

}  // namespace

namespace {

/// What one attempt of a job came to, before it is recorded.
struct Attempt {
  RunOutput out;
  std::string error;  ///< empty: the runner returned
  int exit_code = kExitOk;
  bool permanent = false;  ///< the error is the job's own (ConfigError, NumericalFailure): no retry
  int threads = 1;
  double wall_s = 0;
  bool lease_lost = false, progress_saved = false;
};

/// One worker process's loop: claim a job, verify its bed, run it beside a heartbeat thread, and
/// record the outcome (done, failed, released, given back, fenced out) in the campaign.
class Worker {
 public:
  Worker(const WorkerOptions& o, const RunnerTable& runners)
      : o_(o),
        runners_(runners),
        db_(o.db_path.string()),
        paths_(o.db_path, o.files),
        who_(make_identity(o.code_version, o.threads)),
        // Renew at least 4 times per lease, and report progress at least every 2 s.
        heartbeat_s_(o.heartbeat_s > 0 ? o.heartbeat_s : std::min(o.lease_s / 4, 2.0)),
        with_db_(db_, o.db_path.string(), o.db_outage_s) {
    check_campaign(db_);  // never creates a schema: `work` opened the campaign with open_campaign
    std::error_code ec;
    for (const std::string& d : output_folders()) fs::create_directories(paths_.root / d, ec);
    largest_ = with_db_([&] { return largest_output(db_); });
  }

  WorkerReport run() {
    long ran = 0;
    while (!queue::stop_requested().load() && (o_.max_jobs < 0 || ran < o_.max_jobs)) {
      if (detail::supervisor_gone()) {
        std::fprintf(stderr, "worker %d: its supervisor is gone; stopping\n", who_.pid);
        queue::stop_requested().store(true);
        break;
      }
      const Room room = room_for_output();
      if (room == Room::stop) break;
      if (room == Room::wait) continue;
      bool idle_stop = false;
      const std::optional<Claim> c = next_claim(idle_stop);
      if (idle_stop) break;
      if (!c) continue;
      ++ran;
      if (o_.verbose)
        std::fprintf(stderr, "worker %d: %s job %s attempt %d\n", who_.pid, kind_name(c->kind), c->job_id.c_str(),
                     c->attempt);
      if (!dependency_verified(*c)) continue;
      if (record(*c, run_attempt(*c)) == Next::stop) break;
    }
    if (queue::stop_requested().load()) rep_.interrupted = true;
    return rep_;
  }

 private:
  enum class Room { ok, wait, stop };
  enum class Next { go_on, stop };

  const WorkerOptions& o_;
  const RunnerTable& runners_;
  db::Database db_;
  const CampaignPaths paths_;
  const WorkerIdentity who_;
  const double heartbeat_s_;
  Reconnecting with_db_;
  std::unique_ptr<db::Database> beat_db_;  // the heartbeat thread's own connection, kept across jobs
  std::int64_t largest_ = 0;               // the largest output so far: what the next one may need
  WorkerReport rep_;

  [[nodiscard]] std::string full_now() const { return disk_full(paths_, o_.min_free_bytes, largest_); }
  [[nodiscard]] fs::path tmp_of(const Claim& c) const {
    return paths_.tmp() / (prefix_of(c) + "out" + kind_info(c.kind).extension);
  }
  static std::string prefix_of(const Claim& c) { return fmt::format("{}.a{}.", c.job_id, c.attempt); }

  /// The files root's disk: room for the next output, wait for space (--follow), or stop.
  Room room_for_output() {
    const std::string full = full_now();
    if (full.empty() && rep_.disk_full.empty()) return Room::ok;
    if (!o_.follow) {
      if (rep_.disk_full.empty()) rep_.disk_full = full;
      std::fprintf(stderr, "worker %d: %s\n", who_.pid, rep_.disk_full.c_str());
      return Room::stop;
    }
    rep_.disk_full.clear();  // --follow: wait for space
    sleep_interruptible(std::max(o_.poll_s, 1.0));
    return full.empty() ? Room::ok : Room::wait;
  }

  /// The next job (expired leases are reclaimed on the way); none when nothing is runnable now,
  /// with `stop` set when nothing is left to wait for either.
  std::optional<Claim> next_claim(bool& stop) {
    Reclaimed lost;
    std::optional<Claim> c;
    try {
      c = with_db_([&] {
        lost = Reclaimed{};
        return claim(db_, who_, paths_, o_.lease_s, &lost);
      });
    } catch (const db::DbError& e) {
      if (!e.busy()) throw;
      sleep_interruptible(0.05 + 0.1 * (getpid() % 7) / 7.0);  // busy beyond the timeout: retry with jitter
      return std::nullopt;
    }
    if (lost.lost > 0) {
      rep_.reclaimed += lost.lost;
      remove_lost_files(paths_, lost);
      if (o_.verbose)
        std::fprintf(stderr, "worker %d: requeued %d job(s) with expired leases (%d dead)\n", who_.pid, lost.lost,
                     lost.dead);
    }
    if (!c) {
      if (!o_.follow && !with_db_([&] { return work_remains(db_); })) stop = true;
      if (!stop) sleep_interruptible(o_.poll_s);
    }
    return c;
  }

  /// The dependency's output is verified before the job uses it (a drop's bed: a changed bit changes
  /// every drop's results). A mismatch sends the dependency back to be made again and the job to
  /// wait for it (false).
  bool dependency_verified(const Claim& c) {
    if (c.dep_output_rel.empty() || c.dep_sha256.empty()) return true;
    std::error_code ec;
    const fs::path dep = paths_.abs(c.dep_output_rel);
    const std::string found = fs::exists(dep, ec) ? queue::sha256_file(dep) : std::string("missing");
    if (found == c.dep_sha256) return true;
    const std::string& kind = c.dep_kind;
    const std::string why = fmt::format(
        "{} checksum mismatch: '{}' of {} job {} has sha256 {}, recorded {}; it is made again and job {} waits for it",
        kind, dep.string(), kind, c.dep_job_id, found, c.dep_sha256, c.job_id);
    std::fprintf(stderr, "worker %d: job %s: %s\n", who_.pid, c.job_id.c_str(), why.c_str());
    if (with_db_([&] { return dependency_mismatch(db_, c, why); }))
      ++rep_.failed;
    else
      ++rep_.fenced_out;
    return false;
  }

  /// The threads this job gets: a bed job running alone gets the pool's.
  int threads_for(const Claim& c) {
    try {
      const int threads = with_db_([&] { return threads_for_claim(db_, c, o_.threads, o_.pool_threads); });
      if (threads != o_.threads && o_.verbose)
        std::fprintf(stderr, "worker %d: %s job %s runs alone: %d threads\n", who_.pid, kind_name(c.kind),
                     c.job_id.c_str(), threads);
      return threads;
    } catch (const db::DbError& e) {
      if (!e.busy()) throw;  // busy: run with the worker's own threads
      return o_.threads;
    }
  }

  /// Runs the job's runner beside the heartbeat thread; errors are caught and classified.
  Attempt run_attempt(const Claim& c) {
    Attempt a;
    a.threads = threads_for(c);
    detail::JobSignals sig;
    std::thread beat(detail::heartbeat_loop, std::cref(o_), std::cref(c), std::ref(sig), heartbeat_s_,
                     std::ref(beat_db_));
    const auto t0 = std::chrono::steady_clock::now();
    try {
      const auto runner = runners_.find(c.kind);
      if (runner == runners_.end())
        throw ConfigError(fmt::format("job {}: no runner for kind '{}' in this build", c.job_id, kind_name(c.kind)));
      RunContext ctx{c,
                     tmp_of(c),
                     c.dep_output_rel.empty() ? fs::path() : paths_.abs(c.dep_output_rel),
                     a.threads,
                     [&sig](const std::string& phase, double f, const std::string& detail) {
                       std::lock_guard g(sig.m);
                       sig.phase = phase;
                       sig.fraction = f;
                       sig.detail = detail;
                     },
                     &sig.stop,
                     o_.bed_cache,
                     paths_.root / "checkpoints" / (c.job_id + ".ckpt.h5"),
                     o_.checkpoint_interval_s,
                     &sig.progress_saved,
                     o_.max_memory_bytes};
      a.out = runner->second(ctx);
      check_outputs(c.kind, a.out);  // before the output is stored as the job's
    } catch (const OutputError& e) {
      a.error = fmt::format("logic error: {}", e.what());
      a.exit_code = kExitFailure;
      a.permanent = true;  // the program's mistake: every attempt would report the same
    } catch (const ConfigError& e) {
      a.error = e.what();
      a.exit_code = kExitUsage;
      a.permanent = true;
    } catch (const NumericalFailure& e) {
      a.error = fmt::format("numerical failure at step {}, particle {}: {}", e.step(), e.particle(), e.what());
      a.exit_code = kExitNumerical;
      a.permanent = true;
    } catch (const std::bad_alloc&) {
      // A retry asks for the same memory: the job's sizes exceed this machine.
      a.error = "out of memory: the job asked for more memory than this machine gives it (a retry would ask again)";
      a.exit_code = kExitFailure;
      a.permanent = true;
    } catch (const std::exception& e) {
      a.error = e.what();
      a.exit_code = kExitFailure;
    }
    {
      std::lock_guard g(sig.m);
      sig.finished = true;
    }
    sig.cv.notify_all();
    beat.join();
    a.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    a.lease_lost = sig.lease_lost.load();
    a.progress_saved = sig.progress_saved.load();
    return a;
  }

  /// Records the attempt's outcome; stop after a release (the worker was told to stop).
  Next record(const Claim& c, Attempt a) {
    const fs::path tmp = tmp_of(c);
    if (a.lease_lost) {
      // Someone else holds the job now: discard everything of this attempt.
      remove_tmp_of(paths_.tmp(), prefix_of(c));
      ++rep_.fenced_out;
      return Next::go_on;
    }
    if (queue::stop_requested().load() && (!a.error.empty() || !fs::exists(tmp))) {
      released(c, a);
      return Next::stop;
    }
    if (a.error.empty() && !fs::exists(tmp)) {
      a.error = fmt::format("job {} finished but wrote no output at '{}'", c.job_id, tmp.string());
      a.exit_code = kExitFailure;
    }
    if (!a.error.empty()) {
      remove_tmp_of(paths_.tmp(), prefix_of(c));
      if (environmental(a.error, full_now()))
        give_back_env(c, a.error);
      else
        failed(c, a.error, a.exit_code, a.permanent);
      return Next::go_on;
    }
    Completion done{std::move(a.out), {}, {}, 0};  // the runner's output, moved; store_output adds the file
    if (!store_output(c, done)) return Next::go_on;
    done.report["wall_s"] = a.wall_s;
    done.report["threads"] = a.threads;
    completed(c, done, a.wall_s);
    return Next::go_on;
  }

  /// The worker was told to stop: the job goes back, its release counted (a stall unless the
  /// attempt saved progress).
  void released(const Claim& c, const Attempt& a) {
    remove_tmp_of(paths_.tmp(), prefix_of(c));
    const std::string why = a.error.empty()
                                ? "interrupted by SIGINT/SIGTERM; lease released"
                                : fmt::format("interrupted by SIGINT/SIGTERM ({}); lease released", a.error);
    const std::string state = with_db_([&] { return release(db_, c, why, o_.max_releases, a.progress_saved); });
    ++rep_.released;
    rep_.interrupted = true;
    if (o_.verbose)
      std::fprintf(stderr, "worker %d: job %s released (interrupted)%s\n", who_.pid, c.job_id.c_str(),
                   state == "dead"
                       ? fmt::format("; stopped after {} releases in a row without progress", o_.max_releases).c_str()
                       : "");
  }

  /// An attempt that failed for its environment goes back uncounted; the worker stops claiming.
  void give_back_env(const Claim& c, const std::string& error) {
    const std::string full = full_now();
    with_db_([&] { return give_back(db_, c, "environmental, not counted: " + error); });
    ++rep_.released;
    rep_.disk_full = full.empty() ? error : full;
    std::fprintf(stderr, "worker %d: job %s given back, not counted: %s\n", who_.pid, c.job_id.c_str(),
                 rep_.disk_full.c_str());
  }

  void failed(const Claim& c, const std::string& error, int exit_code, bool permanent) {
    const std::string state = with_db_([&] { return fail(db_, c, error, exit_code, permanent, o_.backoff_base_s); });
    ++(state == "dead" ? rep_.dead : state == "failed" ? rep_.failed : rep_.fenced_out);
    std::fprintf(stderr, "worker %d: job %s attempt %d failed (%s): %s\n", who_.pid, c.job_id.c_str(), c.attempt,
                 state.empty() ? "fenced out" : state.c_str(), error.c_str());
  }

  /// Output: fsync, rename to its final name, fsync the directory, checksum. false when it could
  /// not be stored (the attempt is given back or failed here).
  bool store_output(const Claim& c, Completion& done) {
    const fs::path tmp = tmp_of(c), final_path = paths_.abs(c.output_rel);
    try {
      fs::create_directories(final_path.parent_path());
      fsync_path(tmp);
      fs::rename(tmp, final_path);
      fsync_path(final_path.parent_path());
      remove_tmp_of(paths_.tmp(), prefix_of(c));
      done.output_rel = c.output_rel;
      done.sha256 = queue::sha256_file(final_path);
      done.bytes = static_cast<std::int64_t>(fs::file_size(final_path));
      return true;
    } catch (const std::exception& e) {
      // The file vanished or the disk is full: this attempt fails, the worker goes on.
      std::error_code ec;
      remove_tmp_of(paths_.tmp(), prefix_of(c));
      fs::remove(final_path, ec);
      const std::string why =
          fmt::format("job {}: cannot store its output at '{}': {}", c.job_id, final_path.string(), e.what());
      if (environmental(why, full_now())) {
        give_back_env(c, why);
        return false;
      }
      failed(c, why, 1, false);
      return false;
    }
  }

  void completed(const Claim& c, const Completion& done, double wall_s) {
    bool retried = false;  // after a lost connection the completion may have gone through
    bool ok = false;
    try {
      ok = with_db_([&] {
        if (retried && completed_already(db_, c)) return true;
        retried = true;
        return complete(db_, c, done);
      });
    } catch (const std::exception& e) {
      if (const auto* d = dynamic_cast<const db::DbError*>(&e); d && (d->busy() || d->connection_lost())) throw;
      // The results row was refused (rolled back with the rest of the completion): the attempt
      // fails, its output removed, instead of the worker.
      std::error_code ec;
      fs::remove(paths_.abs(c.output_rel), ec);
      failed(c, fmt::format("job {}: its completion was refused: {}", c.job_id, e.what()), kExitFailure,
             dynamic_cast<const OutputError*>(&e) != nullptr);
      return;
    }
    if (ok) {
      ++rep_.done;
      largest_ = std::max(largest_, done.bytes);
      if (o_.verbose) std::fprintf(stderr, "worker %d: job %s done in %.2f s\n", who_.pid, c.job_id.c_str(), wall_s);
      return;
    }
    std::error_code ec;
    fs::remove(paths_.abs(c.output_rel), ec);
    ++rep_.fenced_out;
    std::fprintf(stderr, "worker %d: job %s finished after its lease was taken over; output discarded\n", who_.pid,
                 c.job_id.c_str());
  }
};

}  // namespace

WorkerReport run_worker(const WorkerOptions& o, const RunnerTable& runners) { return Worker(o, runners).run(); }

}  // namespace gravsweep::queue

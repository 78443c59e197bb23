#include "scheduler/queue/worker.h"

#include <fcntl.h>
#include <sys/statvfs.h>
#include <fmt/format.h>
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

namespace gravsweep::queue {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// True when this worker was started by a `work --workers N` supervisor that is gone.
bool supervisor_gone() {
  static const long supervisor = [] {
    const char* s = std::getenv("GRAVSWEEP_SUPERVISOR_PID");
    return s ? std::atol(s) : 0L;
  }();
  return supervisor > 0 && static_cast<long>(getppid()) != supervisor;
}

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

void remove_tmp_of(const fs::path& tmp_dir, const std::string& prefix) {
  std::error_code ec;
  if (!fs::exists(tmp_dir, ec)) return;
  for (const auto& e : fs::directory_iterator(tmp_dir, ec))
    if (e.path().filename().string().rfind(prefix, 0) == 0) fs::remove_all(e.path(), ec);
}

}  // namespace

void fsync_path(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

void write_file_synced(const fs::path& path, const std::string& text) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw std::runtime_error(fmt::format("cannot create '{}': {}", path.string(), std::strerror(errno)));
  std::size_t off = 0;
  while (off < text.size()) {
    const ssize_t n = ::write(fd, text.data() + off, text.size() - off);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      throw std::runtime_error(fmt::format("cannot write '{}': {}", path.string(), std::strerror(err)));
    }
    off += static_cast<std::size_t>(n);
  }
  // A full disk may show only here (delayed allocation): the data is not safe until fsync says so.
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    throw std::runtime_error(fmt::format("cannot write '{}' (fsync): {}", path.string(), std::strerror(err)));
  }
  if (::close(fd) != 0)
    throw std::runtime_error(fmt::format("cannot write '{}' (close): {}", path.string(), std::strerror(errno)));
}

Runner noop_runner() {
  return [](const RunContext& ctx) {
    const json& s = ctx.claim.scenario;
    const double sleep_s = s.value("sleep_s", 0.0);
    const int fail_attempts = s.value("fail_attempts", 0);
    ctx.progress("noop", 0.0, "");
    if (sleep_s > 0) {
      const auto t0 = std::chrono::steady_clock::now();
      for (;;) {
        const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (el >= sleep_s) break;
        if (ctx.stop && ctx.stop->load()) throw std::runtime_error("noop job stopped");
        ctx.progress("noop", el / sleep_s, fmt::format("{:.2f}/{:.2f} s", el, sleep_s));
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    }
    if (ctx.claim.attempt <= fail_attempts)
      throw std::runtime_error(
          fmt::format("noop job asked to fail on attempt {} (fail_attempts={})", ctx.claim.attempt, fail_attempts));
    // A write error (a full disk, no file descriptor left) fails the attempt with its errno.
    write_file_synced(ctx.output_tmp, json{{"job_id", ctx.claim.job_id}, {"attempt", ctx.claim.attempt}}.dump());
    RunOutput out;
    out.metrics["noop_value"] = s.contains("value") ? s["value"] : json(0);
    out.metrics["sleep_s"] = sleep_s;
    return out;
  };
}

WorkerReport run_worker(const WorkerOptions& o, const RunnerTable& runners) {
  WorkerReport rep;
  db::Database db(o.db_path.string());
  check_campaign(db);  // never creates a schema: `work` opened the campaign with open_campaign
  const CampaignPaths paths(o.db_path, o.files);
  const WorkerIdentity who = make_identity(o.code_version, o.threads);
  // Renew at least 4 times per lease, and report progress at least every 2 s.
  const double hb = o.heartbeat_s > 0 ? o.heartbeat_s : std::min(o.lease_s / 4, 2.0);
  std::error_code ec;
  for (const char* d : kOutputFolders) fs::create_directories(paths.root / d, ec);
  std::unique_ptr<db::Database> beat_db;  // the heartbeat thread's own connection, kept across jobs
  Reconnecting with_db(db, o.db_path.string(), o.db_outage_s);
  std::int64_t largest = with_db([&] { return largest_output(db); });
  // An attempt that failed for its environment goes back uncounted; the worker stops claiming.
  const auto give_back_env = [&](const Claim& c, const std::string& error, std::string full) {
    with_db([&] { return give_back(db, c, "environmental, not counted: " + error); });
    ++rep.released;
    rep.disk_full = full.empty() ? error : full;
    std::fprintf(stderr, "worker %d: job %s given back, not counted: %s\n", who.pid, c.job_id.c_str(),
                 rep.disk_full.c_str());
  };
  long ran = 0;
  while (!queue::stop_requested().load() && (o.max_jobs < 0 || ran < o.max_jobs)) {
    if (supervisor_gone()) {
      std::fprintf(stderr, "worker %d: its supervisor is gone; stopping\n", who.pid);
      queue::stop_requested().store(true);
      break;
    }
    if (const std::string full = disk_full(paths, o.min_free_bytes, largest); !full.empty() || !rep.disk_full.empty()) {
      if (!o.follow) {
        if (rep.disk_full.empty()) rep.disk_full = full;
        std::fprintf(stderr, "worker %d: %s\n", who.pid, rep.disk_full.c_str());
        break;
      }
      rep.disk_full.clear();  // --follow: wait for space
      sleep_interruptible(std::max(o.poll_s, 1.0));
      if (!full.empty()) continue;
    }
    Reclaimed lost;
    std::optional<Claim> c;
    try {
      c = with_db([&] {
        lost = Reclaimed{};
        return claim(db, who, paths, o.lease_s, &lost);
      });
    } catch (const db::DbError& e) {
      if (!e.busy()) throw;
      sleep_interruptible(0.05 + 0.1 * (getpid() % 7) / 7.0);  // busy beyond the timeout: retry with jitter
      continue;
    }
    if (lost.lost > 0) {
      rep.reclaimed += lost.lost;
      remove_lost_files(paths, lost);
      if (o.verbose)
        std::fprintf(stderr, "worker %d: requeued %d job(s) with expired leases (%d dead)\n", who.pid, lost.lost,
                     lost.dead);
    }
    if (!c) {
      if (!o.follow && !with_db([&] { return work_remains(db); })) break;
      sleep_interruptible(o.poll_s);
      continue;
    }
    ++ran;
    const auto runner = runners.find(c->kind);
    const std::string ext = kind_info(c->kind).extension;
    const std::string prefix = fmt::format("{}.a{}.", c->job_id, c->attempt);
    const fs::path tmp = paths.tmp() / (prefix + "out" + ext);
    JobSignals sig;
    std::thread beat(heartbeat_loop, std::cref(o), std::cref(*c), std::ref(sig), hb, std::ref(beat_db));
    auto stop_beat = [&] {
      {
        std::lock_guard g(sig.m);
        sig.finished = true;
      }
      sig.cv.notify_all();
      if (beat.joinable()) beat.join();
    };
    RunOutput out;
    std::string error;
    int exit_code = kExitOk;
    bool permanent = false;
    const auto t0 = std::chrono::steady_clock::now();
    if (o.verbose)
      std::fprintf(stderr, "worker %d: %s job %s attempt %d\n", who.pid, kind_name(c->kind), c->job_id.c_str(),
                   c->attempt);
    if (!c->dep_output_rel.empty() && !c->dep_sha256.empty()) {
      // The bed is verified before the drop uses it: a changed bit changes every drop's results.
      const fs::path bed = paths.abs(c->dep_output_rel);
      const std::string found = fs::exists(bed, ec) ? queue::sha256_file(bed) : std::string("missing");
      if (found != c->dep_sha256) {
        stop_beat();
        const std::string why = fmt::format(
            "bed checksum mismatch: '{}' of bed job {} has sha256 {}, recorded {}; the "
            "bed is rebuilt and the drop waits for it",
            bed.string(), c->dep_job_id, found, c->dep_sha256);
        std::fprintf(stderr, "worker %d: job %s: %s\n", who.pid, c->job_id.c_str(), why.c_str());
        if (with_db([&] { return bed_mismatch(db, *c, why); }))
          ++rep.failed;
        else
          ++rep.fenced_out;
        continue;
      }
    }
    int threads = o.threads;
    try {
      threads = with_db([&] { return threads_for_claim(db, *c, o.threads, o.pool_threads); });
      if (threads != o.threads && o.verbose)
        std::fprintf(stderr, "worker %d: bed job %s runs alone: %d threads\n", who.pid, c->job_id.c_str(), threads);
    } catch (const db::DbError& e) {
      if (!e.busy()) throw;  // busy: run with the worker's own threads
    }
    try {
      if (runner == runners.end())
        throw ConfigError(fmt::format("job {}: no runner for kind '{}' in this build", c->job_id, kind_name(c->kind)));
      RunContext ctx{*c,
                     tmp,
                     c->dep_output_rel.empty() ? fs::path() : paths.abs(c->dep_output_rel),
                     threads,
                     [&sig](const std::string& phase, double f, const std::string& detail) {
                       std::lock_guard g(sig.m);
                       sig.phase = phase;
                       sig.fraction = f;
                       sig.detail = detail;
                     },
                     &sig.stop,
                     o.bed_cache,
                     paths.root / "checkpoints" / (c->job_id + ".ckpt.h5"),
                     o.checkpoint_interval_s,
                     &sig.progress_saved};
      out = runner->second(ctx);
    } catch (const ConfigError& e) {
      error = e.what();
      exit_code = kExitUsage;
      permanent = true;
    } catch (const NumericalFailure& e) {
      error = fmt::format("numerical failure at step {}, particle {}: {}", e.step(), e.particle(), e.what());
      exit_code = kExitNumerical;
      permanent = true;
    } catch (const std::exception& e) {
      error = e.what();
      exit_code = kExitFailure;
    }
    stop_beat();
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (sig.lease_lost.load()) {
      // Someone else holds the job now: discard everything of this attempt.
      remove_tmp_of(paths.tmp(), prefix);
      ++rep.fenced_out;
      continue;
    }
    if (queue::stop_requested().load() && (!error.empty() || !fs::exists(tmp))) {
      remove_tmp_of(paths.tmp(), prefix);
      const std::string state = with_db([&] {
        return release(db, *c,
                       error.empty() ? "interrupted by SIGINT/SIGTERM; lease released"
                                     : fmt::format("interrupted by SIGINT/SIGTERM ({}); lease released", error),
                       o.max_releases, sig.progress_saved.load());
      });
      ++rep.released;
      rep.interrupted = true;
      if (o.verbose)
        std::fprintf(stderr, "worker %d: job %s released (interrupted)%s\n", who.pid, c->job_id.c_str(),
                     state == "dead"
                         ? fmt::format("; stopped after {} releases in a row without progress", o.max_releases).c_str()
                         : "");
      break;
    }
    if (error.empty() && !fs::exists(tmp)) {
      error = fmt::format("job {} finished but wrote no output at '{}'", c->job_id, tmp.string());
      exit_code = kExitFailure;
    }
    if (!error.empty() && environmental(error, disk_full(paths, o.min_free_bytes, largest))) {
      remove_tmp_of(paths.tmp(), prefix);
      give_back_env(*c, error, disk_full(paths, o.min_free_bytes, largest));
      continue;
    }
    if (!error.empty()) {
      remove_tmp_of(paths.tmp(), prefix);
      const std::string state = with_db([&] { return fail(db, *c, error, exit_code, permanent, o.backoff_base_s); });
      if (state == "dead")
        ++rep.dead;
      else if (state == "failed")
        ++rep.failed;
      else
        ++rep.fenced_out;
      std::fprintf(stderr, "worker %d: job %s attempt %d failed (%s): %s\n", who.pid, c->job_id.c_str(), c->attempt,
                   state.empty() ? "fenced out" : state.c_str(), error.c_str());
      continue;
    }
    // Output: fsync, rename to its final name, fsync the directory, checksum, record.
    const fs::path final_path = paths.abs(c->output_rel);
    Completion done;
    try {
      fs::create_directories(final_path.parent_path());
      fsync_path(tmp);
      fs::rename(tmp, final_path);
      fsync_path(final_path.parent_path());
      remove_tmp_of(paths.tmp(), prefix);
      done.output_rel = c->output_rel;
      done.sha256 = queue::sha256_file(final_path);
      done.bytes = static_cast<std::int64_t>(fs::file_size(final_path));
    } catch (const std::exception& e) {
      // The file vanished or the disk is full: this attempt fails, the worker goes on.
      remove_tmp_of(paths.tmp(), prefix);
      fs::remove(final_path, ec);
      const std::string why =
          fmt::format("job {}: cannot store its output at '{}': {}", c->job_id, final_path.string(), e.what());
      if (environmental(why, disk_full(paths, o.min_free_bytes, largest))) {
        give_back_env(*c, why, disk_full(paths, o.min_free_bytes, largest));
        continue;
      }
      const std::string state = with_db([&] { return fail(db, *c, why, 1, false, o.backoff_base_s); });
      ++(state == "dead" ? rep.dead : state == "failed" ? rep.failed : rep.fenced_out);
      std::fprintf(stderr, "worker %d: %s\n", who.pid, why.c_str());
      continue;
    }
    done.metrics = out.metrics;
    done.report = out.report;
    done.report["wall_s"] = secs;
    done.report["threads"] = threads;
    bool retried = false;  // after a lost connection the completion may have gone through
    const bool completed = with_db([&] {
      if (retried && completed_already(db, *c)) return true;
      retried = true;
      return complete(db, *c, done);
    });
    if (completed) {
      ++rep.done;
      largest = std::max(largest, done.bytes);
      if (o.verbose) std::fprintf(stderr, "worker %d: job %s done in %.2f s\n", who.pid, c->job_id.c_str(), secs);
    } else {
      fs::remove(final_path, ec);
      ++rep.fenced_out;
      std::fprintf(stderr, "worker %d: job %s finished after its lease was taken over; output discarded\n", who.pid,
                   c->job_id.c_str());
    }
  }
  if (queue::stop_requested().load()) rep.interrupted = true;
  return rep;
}

}  // namespace gravsweep::queue

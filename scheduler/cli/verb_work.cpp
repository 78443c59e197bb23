// `gravsweep work`: worker processes that claim and run jobs until none is left.
#include <fmt/format.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "scheduler/pipeline/build_version.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/campaign_options.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/pipeline/job_checkpoint.h"
#include "scheduler/sweep/spec.h"
#include "scheduler/queue/stop.h"
#include "scheduler/sweep/sweep_kind.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/spawn.h"
#include "scheduler/queue/worker.h"

namespace gravsweep::cli {

namespace {

/// `work --max-memory` by default: this share of the machine's memory per job.
constexpr double kDefaultMemoryShare = 0.8;

struct WorkOptions {
  std::string db = "campaign.db";
  std::string files;
  int workers = 1;
  int threads = 0;
  int pool_threads = 0;  ///< set by the supervisor for its workers (0: --threads)
  bool follow = false;
  double lease_s = 60;
  double heartbeat_s = 0;
  double poll_s = 0.5;
  double backoff_s = 2.0;
  int max_releases = queue::kDefaultMaxReleases;
  double db_outage_s = 300;
  double min_free_mb = 64;
  long max_jobs = -1;
  bool quiet = false;
  std::string bed_cache;  ///< --bed-cache: prepared beds shared between campaigns (pipeline/bed_cache.h)
  double checkpoint_interval_s = pipeline::kDefaultCheckpointInterval_s;  ///< --checkpoint-interval
  double max_memory_mb = 0;  ///< --max-memory; 0: kDefaultMemoryShare of the machine's
};

/// Exit code after the workers stopped: 4 when some job is dead.
int final_code(const std::string& db_path) {
  db::Database db(db_path);
  db::Statement st(db, "SELECT count(*) FROM jobs WHERE state='dead'");
  st.step();
  return st.get_int(0) > 0 ? kExitIncomplete : kExitOk;
}

/// The command line of one worker process: this binary again with --workers 1 and the
/// supervisor's options (each child opens its own database connection after exec).
std::vector<std::string> worker_args(const WorkOptions& o, int threads) {
  std::vector<std::string> args = {"work",
                                   "--db",
                                   o.db,
                                   "--workers",
                                   "1",
                                   "--threads",
                                   std::to_string(threads),
                                   "--pool-threads",
                                   std::to_string(threads * o.workers),
                                   "--lease",
                                   fmt::format("{}", o.lease_s),
                                   "--poll",
                                   fmt::format("{}", o.poll_s),
                                   "--backoff",
                                   fmt::format("{}", o.backoff_s),
                                   "--max-releases",
                                   std::to_string(o.max_releases),
                                   "--db-outage",
                                   fmt::format("{}", o.db_outage_s),
                                   "--min-free-mb",
                                   fmt::format("{}", o.min_free_mb)};
  if (!o.files.empty()) args.insert(args.end(), {"--files", o.files});
  if (o.heartbeat_s > 0) args.insert(args.end(), {"--heartbeat", fmt::format("{}", o.heartbeat_s)});
  if (o.follow) args.push_back("--follow");
  if (!o.bed_cache.empty()) args.insert(args.end(), {"--bed-cache", o.bed_cache});
  args.insert(args.end(), {"--checkpoint-interval", fmt::format("{}", o.checkpoint_interval_s)});
  if (o.max_memory_mb > 0) args.insert(args.end(), {"--max-memory", fmt::format("{}", o.max_memory_mb)});
  if (o.quiet) args.push_back("--quiet");
  if (o.max_jobs >= 0) args.insert(args.end(), {"--max-jobs", std::to_string(o.max_jobs)});
  return args;
}

/// Forks `n` children that exec `args` with the signal mask `old` restored. Workers die with
/// their supervisor: SIGTERM when it dies (any way, SIGKILL included; kept across exec), and the
/// worker checks its parent too (queue::run_worker) in case it died before the prctl.
std::vector<pid_t> fork_workers(int n, const std::vector<std::string>& args, const sigset_t& old) {
  const std::string exe = queue::self_exe();
  const pid_t supervisor = getpid();
  const std::string supervisor_env = std::to_string(supervisor);
  std::vector<pid_t> kids;
  for (int i = 0; i < n; ++i) {
    pid_t pid = fork();
    if (pid < 0) throw std::runtime_error("fork failed");
    if (pid == 0) {
      prctl(PR_SET_PDEATHSIG, SIGTERM);
      if (getppid() != supervisor) _exit(kExitInterrupted);
      setenv("GRAVSWEEP_SUPERVISOR_PID", supervisor_env.c_str(), 1);
      sigprocmask(SIG_SETMASK, &old, nullptr);
      std::vector<char*> argv{const_cast<char*>(exe.c_str())};
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(exe.c_str(), argv.data());
      _exit(kExitExecFailed);
    }
    kids.push_back(pid);
  }
  return kids;
}

/// How the worker processes ended.
struct WorkersEnded {
  bool interrupted = false;  ///< a signal reached the supervisor, or a worker was interrupted
  int failures = 0;          ///< workers that exited with another code than 0 or 4
};

/// Waits for every child, forwarding SIGINT/SIGTERM (blocked in `signals`) to them.
WorkersEnded wait_for_workers(std::vector<pid_t> kids, const sigset_t& signals) {
  WorkersEnded e;
  std::size_t alive = kids.size();
  while (alive > 0) {
    // Wait for a child or a signal, whichever comes first.
    timespec ts{0, 200'000'000};
    siginfo_t info{};
    const int sig = sigtimedwait(&signals, &info, &ts);
    if (sig == SIGINT || sig == SIGTERM) {
      e.interrupted = true;
      for (pid_t k : kids)
        if (k > 0) kill(k, SIGTERM);
    }
    int status = 0;
    pid_t done;
    while ((done = waitpid(-1, &status, WNOHANG)) > 0) {
      for (auto& k : kids) {
        if (k != done) continue;
        k = -1;
        --alive;
        const int code = WIFEXITED(status) ? WEXITSTATUS(status) : kExitSignalBase + WTERMSIG(status);
        if (code == kExitInterrupted)
          e.interrupted = true;
        else if (code != kExitOk && code != kExitIncomplete) {
          ++e.failures;
          fmt::print(stderr, "gravsweep work: worker {} exited with code {}\n", done, code);
        }
      }
    }
  }
  return e;
}

int supervise(const WorkOptions& o, int threads) {
  const std::vector<std::string> args = worker_args(o, threads);
  // Block SIGINT/SIGTERM here while forking; the supervisor forwards them to the children.
  sigset_t set, old;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigprocmask(SIG_BLOCK, &set, &old);
  const std::vector<pid_t> kids = fork_workers(o.workers, args, old);
  if (!o.quiet)
    fmt::print(stderr, "gravsweep work: {} worker processes ({} threads each) on {}\n", o.workers, threads, o.db);
  const WorkersEnded e = wait_for_workers(kids, set);
  sigprocmask(SIG_SETMASK, &old, nullptr);
  if (e.interrupted) return kExitInterrupted;
  if (e.failures > 0) return kExitFailure;
  return final_code(o.db);
}

int run_work(const WorkOptions& o) {
  // Refuses what is not a campaign before any worker starts (migrates a version-1 campaign).
  // Refuses a files root of another campaign before any worker deletes a file in it.
  {
    db::Database db = queue::open_campaign(o.db, queue::OpenMode::write, o.files);
    queue::bind_files_root(db, queue::CampaignPaths(o.db, o.files));
  }
  if (o.heartbeat_s > 0 && o.heartbeat_s * 2 > o.lease_s)
    throw UsageError(
        fmt::format("--heartbeat: found {} s, expected at most half of --lease ({} s), or the lease "
                    "lapses between heartbeats",
                    o.heartbeat_s, o.lease_s));
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = o.threads > 0 ? o.threads : std::max(1, cores / std::max(1, o.workers));
  if (o.workers > 1) return supervise(o, threads);
  queue::install_stop_signals();
  queue::WorkerOptions w;
  w.db_path = o.db;
  w.files = o.files;
  w.threads = threads;
  w.pool_threads = std::max(threads, o.pool_threads);
  w.lease_s = o.lease_s;
  w.heartbeat_s = o.heartbeat_s;
  w.follow = o.follow;
  w.poll_s = o.poll_s;
  w.max_jobs = o.max_jobs;
  w.backoff_base_s = o.backoff_s;
  w.max_releases = o.max_releases;
  w.db_outage_s = o.db_outage_s;
  w.min_free_bytes = static_cast<std::int64_t>(o.min_free_mb * 1024 * 1024);
  w.code_version = pipeline::build_version();
  w.verbose = !o.quiet;
  w.bed_cache = o.bed_cache;
  w.checkpoint_interval_s = o.checkpoint_interval_s;
  w.max_memory_bytes =
      o.max_memory_mb > 0 ? o.max_memory_mb * 1024 * 1024 : kDefaultMemoryShare * sweep::machine_memory_bytes();
  const auto rep = queue::run_worker(w, sweep::registered_runners());
  if (!o.quiet)
    fmt::print(stderr,
               "worker {}: {} done, {} failed (will retry), {} dead, {} released, {} fenced out, {} expired leases "
               "reclaimed\n",
               getpid(), rep.done, rep.failed, rep.dead, rep.released, rep.fenced_out, rep.reclaimed);
  if (rep.interrupted) return kExitInterrupted;
  if (!rep.disk_full.empty()) return kExitFailure;  // the reason was printed when the worker stopped
  return final_code(o.db);
}

/// --workers .. --checkpoint-interval: how many workers, their threads, leases, retries, disk and
/// checkpoints.
void add_work_options(CLI::App* sub, WorkOptions& o) {
  sub->add_option("--workers", o.workers, "worker processes")->check(CLI::Range(1, 256))->capture_default_str();
  sub->add_option("--threads", o.threads, "engine threads per worker (0: cores / workers)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  sub->add_option("--pool-threads", o.pool_threads,
                  "threads all the workers hold together (the supervisor passes workers x threads): a bed "
                  "job that runs alone, with nothing else running or claimable, uses them all (0: --threads)")
      ->check(CLI::Range(0, 4096))
      ->capture_default_str();
  sub->add_flag("--follow", o.follow, "keep waiting for new jobs when none is left");
  sub->add_option("--lease", o.lease_s, "lease length, s: a worker silent this long is presumed dead")
      ->check(CLI::Range(0.5, 86400.0))
      ->capture_default_str();
  sub->add_option("--heartbeat", o.heartbeat_s,
                  "heartbeat (lease renewal + progress) interval, s (0: min(lease/4, 2 s))")
      ->check(CLI::Range(0.0, 3600.0))
      ->capture_default_str();
  sub->add_option("--poll", o.poll_s, "wait between claims when nothing is runnable, s")
      ->check(CLI::Range(0.01, 60.0))
      ->capture_default_str();
  sub->add_option("--min-free-mb", o.min_free_mb,
                  "free space, MB, the files root must keep beyond the largest output so far: below it the "
                  "worker claims nothing and stops (exit 1; --follow: waits), and an attempt that failed on a "
                  "full disk goes back without being counted")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  sub->add_option("--db-outage", o.db_outage_s,
                  "seconds a worker keeps reconnecting, with backoff, to a PostgreSQL server that restarted or "
                  "went away before it gives up; its running job goes on meanwhile")
      ->check(CLI::Range(0.0, 86400.0))
      ->capture_default_str();
  sub->add_option("--max-releases", o.max_releases,
                  "a job whose attempts were interrupted (SIGINT/SIGTERM, a Slurm time limit) this many times in a "
                  "row without saving progress (a checkpoint further on) is stopped (dead, with the reason) "
                  "instead of looping; `resume --dead` runs it again")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  sub->add_option("--backoff", o.backoff_s, "retry backoff base, s (base * 2^(attempt-1), capped at 300 s)")
      ->check(CLI::Range(0.0, 3600.0))
      ->capture_default_str();
  sub->add_option("--max-jobs", o.max_jobs, "stop after this many jobs per worker (-1: no limit)")
      ->capture_default_str();
  sub->add_option("--bed-cache", o.bed_cache,
                  "folder of prepared beds shared between campaigns and machines: a bed job whose bed is "
                  "there (<bed job id>.h5 + .sha256, checksum and bed key verified) copies it instead of "
                  "preparing it; a bed job that prepares its bed stores it there");
  sub->add_option("--max-memory", o.max_memory_mb,
                  "MB a job may need (its estimate from the scenario: the bed's grains at 2 kB each); a job above "
                  "it is refused before it allocates, permanently (dead, naming the fields). Default: 80 % of the "
                  "machine's memory")
      ->check(CLI::Range(0.1, 1e9));
  sub->add_option("--checkpoint-interval", o.checkpoint_interval_s,
                  "wall seconds between two checkpoints of a running drop or bed preparation "
                  "(<files>/checkpoints/<job>.ckpt.h5; "
                  "also written at SIGTERM); the next attempt of the job continues from it, bit for bit on "
                  "the same thread count. 0: no checkpoints")
      ->check(CLI::Range(0.0, 1e7))
      ->capture_default_str();
}

}  // namespace

void setup_work(CLI::App& app) {
  auto opt = std::make_shared<WorkOptions>();
  auto* sub = app.add_subcommand(
      "work",
      "Run the campaign's jobs: starts --workers worker processes (one database connection each) that\n"
      "claim jobs (bed preparation before the drops that need it), renew their lease with a\n"
      "heartbeat carrying progress, and record each result with its trace path and checksum. They\n"
      "stop when no job is left (--follow: keep waiting for new ones). A worker killed in any way\n"
      "loses its lease after --lease seconds and another worker takes the job over. SIGINT/SIGTERM\n"
      "stop the current job and give its lease back (exit 130). Exit 4 if some job is dead.\n"
      "A files root with less free space than --min-free-mb plus the largest output so far is full:\n"
      "the worker claims nothing and stops (exit 1), and an attempt that failed on a full disk goes\n"
      "back to the queue without being counted against the job.\n"
      "A bed job that runs alone (nothing else running or claimable: its drops wait for it) gets the\n"
      "threads of all the workers (--workers x --threads), so no core idles while it runs.\n"
      "A running drop or bed preparation is checkpointed every --checkpoint-interval seconds and at\n"
      "SIGTERM (scancel, a Slurm time limit); the job's next attempt continues from there, so a drop\n"
      "or a bed longer than a task's time limit still finishes.\n\n"
      "Examples:\n"
      "  gravsweep work --db campaign.db --workers 2 --threads 1\n"
      "  gravsweep work --db campaign.db --follow          # a worker that waits for new submissions\n"
      "  gravsweep work --db postgresql://me@dbhost:5432/sweep --files /shared/sweep --threads 4");
  add_campaign_options(sub, opt->db, &opt->files);
  add_work_options(sub, *opt);
  sub->add_flag("--quiet", opt->quiet, "no per-job log lines");
  sub->callback([opt]() {
    const int code = run_work(*opt);
    // The worker's own codes (4, 130) after every database handle was closed by run_work's
    // scopes; no exit handlers (main.cpp: HDF5's clean-up after a failed job).
    if (code != kExitOk) throw ExitWith{code, true};
  });
}

}  // namespace gravsweep::cli

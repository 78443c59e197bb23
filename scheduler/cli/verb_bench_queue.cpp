// `gravsweep bench-queue`: the scheduler's own overhead with no-op jobs (claim, heartbeat,
// complete), in jobs per second with 1 and more worker processes, and the time of `status` on a
// large queue.
#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/spawn.h"
#include "scheduler/queue/worker.h"
#include "scheduler/sweep/spec.h"

namespace gravsweep::cli {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct BenchQueueOptions {
  long jobs = 2000;
  std::vector<int> workers{1, 4};
  long status_jobs = 100000;
  std::string dir;
  std::string server;  ///< a PostgreSQL URL: campaigns go to fresh databases on that server
  bool keep = false;
};

/// Where the benchmark's campaigns live: SQLite files in `dir`, or fresh databases on a
/// PostgreSQL server (created from the URL's database, dropped at the end unless kept).
struct BenchStore {
  std::string server;
  fs::path dir;
  std::vector<std::string> created;
  /// A new, empty campaign location named `name`.
  std::string fresh(const std::string& name) {
    if (server.empty()) {
      fs::remove(dir / (name + ".db"));
      return (dir / (name + ".db")).string();
    }
    const std::string db = fmt::format("gravsweep_bench_{}_{}", name, getpid());
    db::Database admin(server);
    admin.exec("DROP DATABASE IF EXISTS " + db);
    admin.exec("CREATE DATABASE " + db);
    created.push_back(db);
    return url_of(db);
  }
  [[nodiscard]] std::string url_of(const std::string& db) const {
    const std::string base = server.substr(0, server.find('?'));
    return base.substr(0, base.rfind('/') + 1) + db;
  }
  [[nodiscard]] fs::path files(const std::string& location) const {
    return server.empty() ? fs::path() : dir / (location.substr(location.rfind('/') + 1) + ".files");
  }
  void drop_all() {
    if (server.empty()) return;
    db::Database admin(server);
    for (const auto& db : created) admin.exec("DROP DATABASE IF EXISTS " + db);
  }
};

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// A noop sweep of n jobs into a fresh database; returns the submit time.
double make_campaign(const std::string& db_path, long n) {
  nlohmann::json doc = {
      {"sweep", "bench"},
      {"job", "noop"},
      {"base", {{"i", 0}}},
      {"axes", {{{"name", "i"}, {"pointer", "/i"}, {"range", {{"start", 0}, {"stop", n - 1}, {"step", 1}}}}}}};
  const auto spec = sweep::load_spec_text(doc.dump(), "<bench-queue>", ".");
  const auto jobs = sweep::expand(spec);
  const auto t0 = Clock::now();
  db::Database db(db_path);
  queue::ensure_schema(db);
  queue::submit(db, spec, jobs);
  return since(t0);
}

std::int64_t count_done(const std::string& db_path) {
  db::Database db(db_path);
  db::Statement st(db, "SELECT count(*) FROM jobs WHERE state='done'");
  st.step();
  return st.get_int(0);
}

/// 1. In-process latency of each operation (one connection, no contention).
void bench_operations(const BenchQueueOptions& o, BenchStore& store) {
  const std::string db_path = store.fresh("ops");
  const long n = std::min<long>(o.jobs, 1000);
  make_campaign(db_path, n);
  db::Database db(db_path);
  const queue::CampaignPaths paths(db_path, store.files(db_path));
  const auto who = queue::make_identity("bench", 1);
  double t_claim = 0, t_beat = 0, t_done = 0;
  long k = 0;
  for (;; ++k) {
    auto t0 = Clock::now();
    auto c = queue::claim(db, who, paths, 60);
    t_claim += since(t0);
    if (!c) break;
    t0 = Clock::now();
    queue::heartbeat(db, *c, 60, 0.5, "noop", "");
    t_beat += since(t0);
    queue::Completion done;
    done.output_rel = c->output_rel;
    done.sha256 = std::string(64, '0');
    done.values = {{"noop_value", k}};
    t0 = Clock::now();
    queue::complete(db, *c, done);
    t_done += since(t0);
  }
  fmt::print("per operation, one process, {} jobs:  claim {:.3f} ms   heartbeat {:.3f} ms   complete {:.3f} ms\n\n", k,
             1e3 * t_claim / std::max(1L, k), 1e3 * t_beat / std::max(1L, k), 1e3 * t_done / std::max(1L, k));
}

/// 2. Worker processes end to end.
void bench_workers(const BenchQueueOptions& o, BenchStore& store, const std::string& exe) {
  fmt::print("{:>8} {:>8} {:>10} {:>10} {:>10}\n", "workers", "jobs", "wall_s", "jobs_per_s", "all_done");
  for (int w : o.workers) {
    const std::string db_path = store.fresh(fmt::format("work_{}", w));
    make_campaign(db_path, o.jobs);
    std::vector<std::string> args{"work",      "--db", db_path,   "--workers", std::to_string(w),
                                  "--threads", "1",    "--quiet", "--poll",    "0.01"};
    if (!store.files(db_path).empty()) args.insert(args.end(), {"--files", store.files(db_path).string()});
    const auto t0 = Clock::now();
    const pid_t pid = queue::spawn_process(exe, args);
    const int code = queue::wait_process(pid);
    const double wall = since(t0);
    const auto done = count_done(db_path);
    fmt::print("{:>8} {:>8} {:>10.2f} {:>10.0f} {:>10}\n", w, o.jobs, wall, static_cast<double>(done) / wall,
               done == o.jobs && code == 0 ? "yes" : fmt::format("NO ({} done, exit {})", done, code));
  }
}

/// 3. status on a large queue.
void bench_status(const BenchQueueOptions& o, BenchStore& store, const std::string& exe) {
  const std::string db_path = store.fresh("status");
  const double submit_s = make_campaign(db_path, o.status_jobs);
  db::Database db(db_path);
  double best = 1e9;
  for (int i = 0; i < 5; ++i) {
    const auto t0 = Clock::now();
    const auto s = queue::status(db);
    best = std::min(best, since(t0));
    if (s.per_sweep.empty()) throw std::runtime_error("bench-queue: status saw no jobs");
  }
  const auto t0 = Clock::now();
  const pid_t pid = queue::spawn_process(exe, {"status", "--db", db_path}, true);
  const int code = queue::wait_process(pid);
  const double cli_s = since(t0);
  fmt::print(
      "\n{} queued jobs: submit {:.2f} s ({:.0f} jobs/s); status query {:.1f} ms (best of 5); "
      "`gravsweep status` process {:.1f} ms (exit {})\n",
      o.status_jobs, submit_s, static_cast<double>(o.status_jobs) / submit_s, 1e3 * best, 1e3 * cli_s, code);
}

void run_bench_queue(const BenchQueueOptions& o) {
  fs::path dir = o.dir;
  if (dir.empty()) {
    std::string tmpl = (fs::temp_directory_path() / "gravsweep-bench-queue-XXXXXX").string();
    if (!mkdtemp(tmpl.data())) throw std::runtime_error("cannot create a temporary directory");
    dir = tmpl;
  }
  fs::create_directories(dir);
  BenchStore store{o.server, dir, {}};
  const std::string exe = queue::self_exe();
  fmt::print(
      "scheduler overhead with no-op jobs on {} (each: claim in one transaction, one heartbeat, output file "
      "written + fsynced + renamed + checksummed, fenced completion with results row)\n\n",
      o.server.empty() ? std::string("SQLite") : "PostgreSQL at " + o.server);

  bench_operations(o, store);
  bench_workers(o, store, exe);
  bench_status(o, store, exe);
  if (!o.keep) store.drop_all();
  if (!o.keep && o.dir.empty())
    fs::remove_all(dir);
  else
    fmt::print("databases kept in {}{}\n", dir.string(), o.server.empty() ? "" : " and on the server");
}

}  // namespace

void setup_bench_queue(CLI::App& app) {
  auto opt = std::make_shared<BenchQueueOptions>();
  auto* sub = app.add_subcommand(
      "bench-queue",
      "Measure the scheduler's own overhead with no-op jobs: the latency of claim, heartbeat and\n"
      "complete in one process, jobs per second with worker processes (each job is claimed, heartbeated,\n"
      "writes and fsyncs a small output, and is completed with its checksum and results row), and\n"
      "the time of `gravsweep status` on a queue of --status-jobs jobs. Uses fresh databases in a\n"
      "temporary directory, or with --postgres fresh databases on that server (created and dropped).\n\n"
      "Examples:\n"
      "  gravsweep bench-queue                              # 2000 jobs, 1 and 4 workers, status on 100,000\n"
      "  gravsweep bench-queue --jobs 500 --workers 1,2,4 --status-jobs 20000\n"
      "  gravsweep bench-queue --postgres postgresql://postgres@127.0.0.1:54329/postgres --workers 1,4,16");
  sub->add_option("--jobs", opt->jobs, "no-op jobs per worker count")
      ->check(CLI::Range(1L, 10000000L))
      ->capture_default_str();
  sub->add_option("--workers", opt->workers, "worker counts, comma separated")->delimiter(',')->capture_default_str();
  sub->add_option("--status-jobs", opt->status_jobs, "queued jobs for the status timing")
      ->check(CLI::Range(1L, 10000000L))
      ->capture_default_str();
  sub->add_option("--dir", opt->dir, "directory for the databases (kept)");
  sub->add_option("--postgres", opt->server,
                  "PostgreSQL URL of a database to connect to for creating the benchmark's "
                  "databases (e.g. postgresql://postgres@127.0.0.1:5432/postgres)");
  sub->add_flag("--keep", opt->keep, "keep the temporary databases");
  sub->callback([opt]() { run_bench_queue(*opt); });
}

}  // namespace gravsweep::cli

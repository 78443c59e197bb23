// `gravsweep status`: per-state counts per sweep, running jobs with progress, stale leases, ETA.
#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "scheduler/pipeline/build_version.h"
#include "scheduler/cli/exit_codes.h"
#include "scheduler/cli/progress.h"
#include "scheduler/cli/campaign_options.h"
#include "results/io/table.h"
#include "scheduler/cli/format_option.h"
#include "scheduler/cli/verbs.h"
#include "scheduler/queue/stop.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/worker.h"

namespace gravsweep::cli {

namespace {

struct StatusOptions {
  std::string db = "campaign.db";
  std::string format = "table";
  int max_running = 20;
  double watch_s = 0;
};

std::string render_status(const queue::Status& s, const std::string& db, double query_s) {
  std::string out;
  std::int64_t total = 0;
  queue::StateCounts all;
  results::Table t({"sweep", "kind", "waiting", "queued", "running", "failed", "done", "dead", "total"},
                   results::kRuledText);
  for (const auto& c : s.per_sweep) {
    t.add({c.sweep, c.kind, std::to_string(c.waiting), std::to_string(c.queued), std::to_string(c.running),
           std::to_string(c.failed), std::to_string(c.done), std::to_string(c.dead), std::to_string(c.total())});
    total += c.total();
    all.waiting += c.waiting, all.queued += c.queued, all.running += c.running, all.failed += c.failed;
    all.done += c.done, all.dead += c.dead;
  }
  out += fmt::format("campaign {}: {} job memberships; {} done, {} dead, {} running, {} to run\n\n", db, total,
                     all.done, all.dead, all.running, all.waiting + all.queued + all.failed);
  out += t.text();
  const double now = queue::now_s();
  if (!s.running.empty()) {
    results::Table r({"job_id", "kind", "attempt", "worker", "phase", "progress_pct", "elapsed_s", "heartbeat_age_s",
                      "lease_left_s", "detail"},
                     results::kRuledText);
    for (const auto& j : s.running)
      r.add({j.job_id, j.kind, std::to_string(j.attempt), j.owner, j.phase, fmt::format("{:.1f}", 100 * j.progress),
             fmt::format("{:.1f}", now - j.started_at), fmt::format("{:.1f}", now - j.heartbeat_at),
             j.stale ? "STALE" : fmt::format("{:.1f}", j.lease_expires - now), j.detail});
    out += fmt::format("\nrunning jobs ({} active, {} stale lease{}):\n", s.active_workers, s.stale_leases,
                       s.stale_leases == 1 ? "" : "s");
    out += r.text();
  }
  if (s.stale_leases > 0)
    out += fmt::format(
        "\n{} stale lease(s): their workers stopped heartbeating; the next claim or `gravsweep resume` "
        "requeues them.\n",
        s.stale_leases);
  if (!s.runtimes.empty()) {
    results::Table k({"kind", "finished", "median_runtime_s", "remaining"}, results::kRuledText);
    for (const auto& r : s.runtimes)
      k.add({r.kind, std::to_string(r.finished), r.finished ? fmt::format("{:.2f}", r.median_s) : "-",
             std::to_string(r.remaining)});
    out += "\nruntimes by kind:\n" + k.text();
  }
  if (all.waiting + all.queued + all.failed + all.running > 0) {
    out += s.eta_s >= 0
               ? fmt::format(
                     "\nETA {} with {} active worker(s) (median runtime of finished jobs of each sweep and kind)\n",
                     format_duration(s.eta_s), std::max<std::int64_t>(1, s.active_workers))
               : "\nETA unknown: no job of some remaining kind has finished yet\n";
  }
  if (s.blocked > 0) out += fmt::format("{} job(s) dead because a bed they need is dead\n", s.blocked);
  if (s.released_attempts > 0)
    out += fmt::format(
        "{} attempt(s) released (interrupted: SIGINT/SIGTERM, a Slurm time limit; not counted against the retry "
        "budget), {} unfinished job(s) among them; {} job(s) stopped after too many releases\n",
        s.released_attempts, s.released_jobs, s.stopped_by_releases);
  if (!s.recent_errors.empty()) {
    out += "\ndead jobs (latest):\n";
    for (const auto& [id, err] : s.recent_errors) out += fmt::format("  {}  {}\n", id, err.substr(0, 160));
  }
  if (!s.dependency_mismatches.empty()) {
    out +=
        fmt::format("\nbeds rebuilt after a checksum mismatch ({} drop(s) noticed):\n", s.dependency_mismatches.size());
    for (const auto& [id, err] : s.dependency_mismatches) out += fmt::format("  drop {}: {}\n", id, err.substr(0, 300));
  }
  out += fmt::format("\n(status query {:.1f} ms)\n", 1000 * query_s);
  return out;
}

void run_status(const StatusOptions& o) {
  db::Database db = queue::open_campaign(o.db, queue::OpenMode::read);
  if (o.watch_s > 0) queue::install_stop_signals();
  do {
    const auto t0 = std::chrono::steady_clock::now();
    const auto s = queue::status(db, static_cast<std::size_t>(o.max_running));
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (o.format == "json") {
      auto j = queue::status_json(s);
      j["query_s"] = secs;
      fmt::print("{}\n", j.dump(2));
    } else {
      if (o.watch_s > 0) fmt::print("\x1b[H\x1b[2J");
      fmt::print("{}", render_status(s, o.db, secs));
      // Provenance: results from another build of gravsweep (like Snakemake's code rerun trigger).
      db::Statement other(db,
                          "SELECT code_version, count(*) FROM results WHERE code_version <> ? GROUP BY code_version "
                          "ORDER BY code_version");
      other.bind(1, std::string(pipeline::build_version()));
      std::int64_t n_other = 0;
      std::string versions;
      while (other.step()) {
        n_other += other.get_int(1);
        if (!versions.empty()) versions += ',';
        versions += other.get_text(0);  // (not "a" + b: GCC 12 warns -Wrestrict on it)
      }
      if (n_other > 0)
        fmt::print("{} result(s) were computed by another code version ({}); this is {}\n", n_other, versions,
                   pipeline::build_version());
    }
    std::fflush(stdout);
    if (o.watch_s <= 0) break;
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.watch_s);
    while (!queue::stop_requested().load() && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  } while (!queue::stop_requested().load());
}

}  // namespace

void setup_status(CLI::App& app) {
  auto opt = std::make_shared<StatusOptions>();
  auto* sub = app.add_subcommand(
      "status",
      "Show a campaign: job counts per state for each sweep and kind, running jobs with their\n"
      "progress and lease, stale leases (workers that stopped heartbeating), median runtimes and an\n"
      "ETA (remaining jobs x median runtime of finished jobs of the same sweep and kind; where that\n"
      "sweep has none yet, what its running jobs project from their progress, else the kind's\n"
      "median / active workers). A running drop's detail gives its simulated time against its cap,\n"
      "its step count and time step, depth and speed, and its last checkpoint (`t=0.4210s of 4s cap\n"
      "step=421000 dt=1e-06s depth=3.10cm ... ckpt t=0.4000s at 14:02:11Z`; or\n"
      "`resumed from t=...` before the first checkpoint of a continued drop).\n"
      "Counts come from indexed queries: fast on 100,000 jobs.\n\n"
      "Examples:\n"
      "  gravsweep status --db campaign.db\n"
      "  gravsweep status --db campaign.db --watch 2        # refresh every 2 s\n"
      "  gravsweep status --db campaign.db --format json");
  add_campaign_options(sub, opt->db, nullptr);
  add_format_option(sub, opt->format, {"table", "json"});  // several tables: no one CSV
  sub->add_option("--max-running", opt->max_running, "running jobs listed at most")->capture_default_str();
  sub->add_option("--watch", opt->watch_s, "refresh every this many seconds (0: once)")->capture_default_str();
  sub->callback([opt]() { run_status(*opt); });
}

}  // namespace gravsweep::cli

// Pilot workers through a real single-node Slurm (tests/common/slurm_cluster.h) on a PostgreSQL
// campaign (tests/common/postgres_server.h), label cluster: `gravsweep slurm submit` runs a tiny
// impact campaign to completion while one array task is scancelled mid-job; `gravsweep slurm
// cancel` stops every worker, which give their leases back; a task killed at its time limit loses
// nothing. Skipped, saying why, when the Slurm daemons or the PostgreSQL server cannot start here.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "campaign_store.h"
#include "db/database.h"
#include "scheduler/queue/canonical.h"
#include "scheduler_test_helpers.h"
#include "tests/common/slurm_cluster.h"

using namespace gravsweep;
using namespace gravsweep::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

/// A Slurm cluster and a PostgreSQL campaign store, or why not (then the test skips).
struct ClusterFixture : ::testing::Test {
  TempDir dir;
  std::string why;
  SlurmCluster* slurm = SlurmCluster::shared(why);
  CampaignStore store{Store::postgres, dir.path};
  void SetUp() override {
    if (!slurm) GTEST_SKIP() << "Slurm not available: " << why;
    if (!store.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << store.skip;
  }
  std::vector<std::string> with_store(std::vector<std::string> args) const {
    const auto s = store.args();
    args.insert(args.end(), s.begin(), s.end());
    return args;
  }
  /// Submits `doc`; then `slurm submit` of `workers` 1-thread pilot workers; returns the array's job id.
  std::string submit_with_workers(const json& doc, int workers) {
    write_text(dir.path / "spec.json", doc.dump());
    auto r = run_cli(with_store({"submit", "spec.json"}), dir.path);
    EXPECT_EQ(r.code, 0) << r.err;
    r = run_cli(with_store({"slurm", "submit", "--workers", std::to_string(workers), "--threads", "1", "--lease", "5"}),
                dir.path);
    EXPECT_EQ(r.code, 0) << r.err;
    const auto at = r.out.find("job array ");
    EXPECT_NE(at, std::string::npos) << r.out;
    return at == std::string::npos ? "" : r.out.substr(at + 10, r.out.find(' ', at + 10) - at - 10);
  }
  /// Waits until `sql` (a count) reaches `n`; false after `timeout_s`.
  bool wait_count(db::Database& db, const std::string& sql, std::int64_t n, double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (sql_int(db, sql) < n) {
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return true;
  }
  /// Every job done by exactly one attempt, no attempt left running, every output present with its checksum.
  void expect_complete_and_exact(db::Database& db, std::int64_t jobs, std::int64_t results) {
    EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), jobs);
    EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='done'"), jobs);
    EXPECT_EQ(sql_int(db, "SELECT count(DISTINCT job_id) FROM attempts WHERE outcome='done'"), jobs);
    EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='running'"), 0);
    EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results"), results);
    EXPECT_EQ(sql_int(db, "SELECT count(DISTINCT job_id) FROM results"), results);
    db::Statement st(db, "SELECT output_path, output_sha256 FROM jobs");
    while (st.step()) {
      const fs::path p = store.files / st.get_text(0);
      ASSERT_TRUE(fs::exists(p)) << p;
      EXPECT_EQ(queue::sha256_file(p), st.get_text(1)) << p;
    }
  }
};

}  // namespace

TEST_F(ClusterFixture, ATinyImpactCampaignCompletesThroughSlurmWithATaskScancelledMidJob) {
  // 2 beds and 8 drops (4 speeds per bed, 6 s simulated: 3-18 s each), 2 pilot workers of 1 thread
  // (this machine's cores). Progress is written at each heartbeat (1.25 s with --lease 5), so the
  // value read may be that old: a drop must outlast the heartbeat by far, and the window read (5-25 %)
  // must end well before the drop does. Seen on 2026-12-02: with 1 s simulated no task was ever seen
  // mid-job (each drop took about 1 s); with 4 s and a window up to 70 % the job was done before the
  // scancel landed. Seen under load (the suite on 2 cores beside a campaign): with a window up to
  // 40 % a 3 s drop read at one heartbeat (about 40 % of it) was done before the scancel landed.
  json base = json::parse(tiny_base());
  base["stop"]["max_time_s"] = 6.0;
  base["at_rest"] = {{"surface_speed_fraction", 1.0}, {"rms_speed_fraction", 1.0}};  // a quick test bed
  // Every drop runs its full time: a drop that came to rest early jumped from 30 % to done
  // between the progress reading and the scancel, and the victim's attempt read "done".
  base["stop"]["hold_time_s"] = 10.0;
  json doc = {{"sweep", "slurm_tiny"},
              {"max_attempts", 4},
              {"base", base},
              {"axes",
               {{{"name", "bed_seed"}, {"pointer", "/bed/seed"}, {"values", {7, 8}}},
                {{"name", "impact_speed_m_s"},
                 {"pointer", "/projectile/impact_speed_m_s"},
                 {"values", {0.4, 0.5, 0.6, 0.7}}}}}};
  const std::string array = submit_with_workers(doc, 2);
  ASSERT_FALSE(array.empty());
  db::Database db(store.location);

  // A task in the middle of a job (well before its end: the cancel must land inside it): its
  // lease names its Slurm task, and status shows it.
  const std::string mid_job =
      "SELECT substr(a.worker, strpos(a.worker, ':slurm=') + 7) || ' ' || a.job_id FROM attempts a JOIN jobs j ON "
      "j.job_id=a.job_id WHERE a.outcome='running' AND j.state='running' AND j.progress > 0.05 AND j.progress < 0.25 "
      "AND a.worker LIKE '%:slurm=" +
      array + "%' ORDER BY j.progress LIMIT 1";
  std::string found;
  for (const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(240);
       found.empty() && std::chrono::steady_clock::now() < end;)
    if ((found = sql_text(db, mid_job)).empty()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_FALSE(found.empty()) << "no Slurm task was ever seen mid-job; squeue: " << slurm->client("squeue")
                              << slurm->log_tail();
  const std::string victim = found.substr(0, found.find(' ')), victim_job = found.substr(found.find(' ') + 1);
  auto r = run_cli({"status", "--db", store.location}, dir.path);
  EXPECT_NE(r.out.find(":slurm=" + victim), std::string::npos) << "status names the Slurm task:\n" << r.out;
  int rc = 0;
  slurm->client("scancel " + victim, &rc);
  EXPECT_EQ(rc, 0);
  std::printf("scancel %s while it ran job %s\n", victim.c_str(), victim_job.c_str());

  // The other task finishes the campaign; the cancelled one gave its lease back on SIGTERM.
  EXPECT_TRUE(slurm->wait_idle(300)) << "tasks still queued or running: " << slurm->client("squeue");
  EXPECT_NO_FATAL_FAILURE(expect_complete_and_exact(db, 10, 8));
  EXPECT_EQ(sql_text(db, "SELECT outcome FROM attempts WHERE job_id='" + victim_job +
                             "' AND worker LIKE '%:slurm=" + victim + "'"),
            "released")
      << "the scancelled worker's attempt";
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='lost'"), 0) << "no lease had to expire";
  EXPECT_EQ(sql_int(db, "SELECT count(DISTINCT substr(worker, strpos(worker, ':slurm='))) FROM attempts"), 2)
      << "both array tasks worked";
  for (const char* task : {"_1.log", "_2.log"})
    EXPECT_TRUE(fs::exists(store.files / "slurm" / (array + task))) << "the task's log in <files>/slurm/";
  r = run_cli({"status", "--db", store.location}, dir.path);
  EXPECT_NE(r.out.find("10 done, 0 dead, 0 running, 0 to run"), std::string::npos) << r.out;
}

TEST_F(ClusterFixture, SlurmCancelStopsEveryWorkerAndTheyGiveTheirLeasesBack) {
  json doc = {
      {"sweep", "slurm_cancel"},
      {"job", "noop"},
      {"base", {{"g", 1.0}, {"sleep_s", 1.0}}},
      {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"range", {{"start", 1}, {"stop", 20}, {"step", 1}}}}}}};
  const std::string array = submit_with_workers(doc, 2);
  ASSERT_FALSE(array.empty());
  db::Database db(store.location);
  ASSERT_TRUE(wait_count(db, "SELECT count(*) FROM attempts WHERE outcome='running'", 2, 120))
      << "two workers never ran at once; squeue: " << slurm->client("squeue") << slurm->log_tail();

  auto r = run_cli(with_store({"slurm", "cancel"}), dir.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("scancel '" + array + "'"), std::string::npos) << r.out;
  EXPECT_TRUE(slurm->wait_idle(60)) << "workers still running after slurm cancel: " << slurm->client("squeue");
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='running'"), 0);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='running'"), 0) << "every lease given back";
  EXPECT_GE(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='released'"), 1);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='lost'"), 0);
  const auto done_before = sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'");
  EXPECT_LT(done_before, 20) << "the cancel came too late to stop anything";

  std::printf("slurm cancel: %lld of 20 jobs done, %lld attempt(s) released\n", static_cast<long long>(done_before),
              static_cast<long long>(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='released'")));

  // Nothing was lost: a local worker finishes the campaign, each job exactly once.
  r = run_cli(with_store({"work", "--workers", "2", "--quiet", "--poll", "0.1"}), dir.path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NO_FATAL_FAILURE(expect_complete_and_exact(db, 20, 20));
}

TEST_F(ClusterFixture, ATaskKilledAtItsTimeLimitLosesNothing) {
  // One pilot worker with a 1 minute limit on 8 jobs of 15 s: Slurm stops it mid-job (SIGTERM,
  // then SIGKILL after KillWait); its job goes back to the queue and a later worker finishes it.
  json doc = {
      {"sweep", "slurm_time"},
      {"job", "noop"},
      {"base", {{"g", 1.0}, {"sleep_s", 15.0}}},
      {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"range", {{"start", 1}, {"stop", 8}, {"step", 1}}}}}}};
  write_text(dir.path / "spec.json", doc.dump());
  ASSERT_EQ(run_cli(with_store({"submit", "spec.json"}), dir.path).code, 0);
  auto r =
      run_cli(with_store({"slurm", "submit", "--workers", "1", "--threads", "1", "--time", "00:01:00", "--lease", "5"}),
              dir.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto at = r.out.find("job array ");
  ASSERT_NE(at, std::string::npos) << r.out;
  const std::string array = r.out.substr(at + 10, r.out.find(' ', at + 10) - at - 10);
  EXPECT_TRUE(slurm->wait_idle(180)) << "the task outlived its time limit: " << slurm->client("squeue");

  std::stringstream log;
  log << std::ifstream(store.files / "slurm" / (array + "_1.log")).rdbuf();
  EXPECT_NE(log.str().find("DUE TO TIME LIMIT"), std::string::npos) << "the task's log:\n" << log.str();
  db::Database db(store.location);
  const auto done_before = sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'");
  EXPECT_GE(done_before, 3) << "a minute holds at least 3 jobs of 15 s";
  EXPECT_LT(done_before, 8);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='released'"), 1) << "stopped mid-job";
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome IN ('running', 'lost')"), 0);
  std::printf("time limit: %lld of 8 jobs done in the task's minute\n", static_cast<long long>(done_before));

  r = run_cli(with_store({"work", "--workers", "4", "--quiet", "--poll", "0.1"}), dir.path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NO_FATAL_FAILURE(expect_complete_and_exact(db, 8, 8));
}

TEST_F(ClusterFixture, ADropLongerThanATaskTimeLimitCompletesAcrossTasksFromItsCheckpoints) {
  // One drop needing several times a task's 1-minute limit (180 s simulated at 1 m/s2, about
  // 1.7-1.9 s of wall time each on one thread here; a stop speed no grain jitter falls below, so
  // it runs to the cap; 200 Hz trace). Slurm ends a task some time after its limit (its timer
  // ticks, then SIGTERM and KillWait): two tasks once held 155 s of a drop, so the drop is long
  // enough to outlast two tasks however late they are stopped. Tasks are submitted one after the other: each is stopped
  // at its time limit (SIGTERM), checkpoints the drop and gives its lease back; the next one continues.
  json base = json::parse(tiny_base());
  base["gravity_m_s2"] = 1.0;
  base["stop"] = {{"max_time_s", 180.0}, {"speed_m_s", 1e-12}, {"hold_time_s", 10.0}};
  base["at_rest"] = {{"surface_speed_fraction", 1.0}, {"rms_speed_fraction", 1.0}};  // a quick test bed
  base["output"] = {{"sample_rate_hz", 200.0}, {"filter_cutoff_hz", 50.0}};
  json doc = {
      {"sweep", "slurm_long"},
      {"base", base},
      {"axes", {{{"name", "impact_speed_m_s"}, {"pointer", "/projectile/impact_speed_m_s"}, {"values", {0.5}}}}}};
  write_text(dir.path / "spec.json", doc.dump());
  ASSERT_EQ(run_cli(with_store({"submit", "spec.json"}), dir.path).code, 0);
  db::Database db(store.location);
  // 4-6 tasks on an idle 2-core host, about 8 on a host 1.5x slower; every task saves progress, so
  // the release limit (5 in a row without progress) never stops the drop however many it takes.
  constexpr int kMaxTasks = 16;
  constexpr double kInterval_s = 20;
  int tasks = 0;
  auto unfinished = [&] {
    return sql_int(db, "SELECT count(*) FROM jobs WHERE state IN ('waiting', 'queued', 'running', 'failed')") > 0;
  };
  while (tasks < kMaxTasks && unfinished()) {
    const auto r = run_cli(with_store({"slurm", "submit", "--workers", "1", "--threads", "1", "--time", "00:01:00",
                                       "--lease", "5", "--checkpoint-interval", fmt::format("{}", kInterval_s)}),
                           dir.path);
    ASSERT_EQ(r.code, 0) << r.err;
    ++tasks;
    ASSERT_TRUE(slurm->wait_idle(240)) << "the task outlived its time limit: " << slurm->client("squeue");
  }
  auto rows = [&db](const std::string& sql) {  // each row's text columns, joined
    std::string out;
    db::Statement st(db, sql);
    while (st.step()) out += fmt::format("\n  {} | {} | {}", st.get_text(0), st.get_text(1), st.get_text(2));
    return out;
  };
  ASSERT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), 2)
      << "not done after " << tasks << " tasks; jobs:" << rows("SELECT kind, state, coalesce(last_error, '') FROM jobs")
      << "\nattempts:"
      << rows("SELECT outcome, CAST(coalesce(runtime_s, 0) AS TEXT), coalesce(error, '') FROM attempts");
  const std::string drop = "(SELECT job_id FROM jobs WHERE kind='drop')";
  const auto released = sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='released' AND job_id=" + drop);
  EXPECT_GE(released, 2) << "the drop outlasted at least two tasks";
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='released' AND job_id=" + drop +
                            " AND error LIKE '%checkpoint%'"),
            released)
      << "each released attempt says where its checkpoint is";
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome IN ('lost', 'running', 'failed')"), 0);
  EXPECT_EQ(sql_int(db, "SELECT checkpoint_resumes FROM results WHERE kind='drop'"), released);
  // At most one checkpoint interval of work lost per task: the attempts' time beyond the drop's
  // own (counted up to each checkpoint it continued from).
  db::Statement st(db, "SELECT (SELECT sum(runtime_s) FROM attempts WHERE job_id=" + drop +
                           "), wall_time_s FROM results WHERE kind='drop'");
  ASSERT_TRUE(st.step());
  const double attempts_s = st.get_double(0), drop_s = st.get_double(1);
  EXPECT_LT(attempts_s - drop_s, static_cast<double>(released + 1) * kInterval_s)
      << attempts_s << " s of attempts for a drop of " << drop_s << " s";
  EXPECT_TRUE(fs::is_empty(store.files / "checkpoints")) << "the checkpoint outlived the drop";
  std::printf("long drop: %d tasks, %lld released attempts, %.1f s of attempts for %.1f s of drop\n", tasks,
              static_cast<long long>(released), attempts_s, drop_s);
}

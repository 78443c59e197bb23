// The crash test of the issue, with the real engine: 3 workers on a 60-job campaign of tiny
// scenarios (4 beds, 56 drops), one a plain `work` process and two under a `work --workers 2`
// supervisor; in turn the worker and the supervisor are killed with SIGKILL while a job is in the
// middle (the supervisor's workers must die with it), and restarted. At the end every job is done
// exactly once, no result row is duplicated, every trace exists with its recorded checksum, no
// file is orphaned, and PRAGMA integrity_check is ok. On both backends: SQLite, and a throwaway
// PostgreSQL server (scheduler_postgres_tests, label postgres).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include "db/database.h"
#include "scheduler/pipeline/impact_runners.h"
#include "scheduler/queue/canonical.h"
#include "campaign_store.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

/// True while `pid` exists and is not a zombie.
bool process_alive(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return false;
  const auto close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] != 'Z';
}

/// The live children of `parent` (from /proc/<pid>/stat, field 4).
std::vector<pid_t> children_of(pid_t parent) {
  std::vector<pid_t> out;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat(e.path() / "stat");
    std::string line;
    if (!std::getline(stat, line)) continue;
    const auto close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    char state = 0;
    long ppid = 0;
    rest >> state >> ppid;
    if (ppid == parent && state != 'Z') out.push_back(static_cast<pid_t>(std::stol(name)));
  }
  return out;
}

/// `a` followed by `b`.
std::vector<std::string> cat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

/// What the storm did.
struct Storm {
  int worker_kills = 0, supervisor_kills = 0;
  int orphans = 0;  ///< workers that outlived their SIGKILLed supervisor by 5 s
};

/// Runs the campaign of `doc` with 3 workers: a `work` process and, when `with_supervisor`, a
/// `work --workers 2` supervisor (else two more `work` processes). SIGKILLs up to max_kills times, each time
/// one victim caught mid-job: worker 0, or (every other kill, when `with_supervisor`) the
/// supervisor while one of its workers is mid-job; each victim is restarted. Then checks the
/// campaign end to end.
void crash_campaign(Store store_kind, const json& doc, std::int64_t total, std::int64_t with_results,
                    const std::vector<std::string>& param_columns, int min_kills, int max_kills,
                    bool with_supervisor = false) {
  TempDir d;
  const CampaignStore store(store_kind, d.path);
  if (!store.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << store.skip;
  write_text(d.path / "spec.json", doc.dump(2));
  auto r = run_cli(cat({"submit", "spec.json"}, store.args()), d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_NE(r.out.find(fmt::format("{} new, 0 already present", total)), std::string::npos) << r.out;

  const std::string db_path = store.location;
  const std::vector<std::string> work_args =
      cat({"work", "--threads", "1", "--lease", "3", "--heartbeat", "0.3", "--poll", "0.1", "--backoff", "0.1"},
          store.args());
  std::vector<std::string> sup_args = work_args;
  sup_args.insert(sup_args.end(), {"--workers", "2", "--quiet"});
  // Slot 0: a plain worker; then the supervisor of two workers, or two more plain workers.
  std::vector<pid_t> workers{start_cli(work_args, d.path / "w0.log")};
  if (with_supervisor)
    workers.push_back(start_cli(sup_args, d.path / "sup.log"));
  else
    for (int i = 1; i < 3; ++i) workers.push_back(start_cli(work_args, d.path / fmt::format("w{}.log", i)));

  db::Database db(db_path);
  Storm storm;
  int kills = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(150);
  while (kills < max_kills && std::chrono::steady_clock::now() < deadline) {
    // The victim: worker 0, or the supervisor (slot 1) on every other kill.
    const bool sup_turn = with_supervisor && kills % 2 == 1;
    const pid_t victim = workers[sup_turn ? 1 : 0];
    std::vector<pid_t> watched = sup_turn ? children_of(victim) : std::vector<pid_t>{victim};
    std::string pids;
    for (pid_t w : watched) pids += (pids.empty() ? "" : ",") + std::to_string(w);
    // Wait until the victim (or one of its workers) is in the middle of a job: it holds a lease
    // and has reported progress.
    const std::string q = fmt::format(
        "SELECT count(*) FROM attempts a JOIN jobs j ON j.job_id=a.job_id WHERE a.pid IN ({}) AND "
        "a.outcome='running' AND j.state='running' AND j.progress > 0.2 AND j.progress < 0.9",
        pids.empty() ? "-1" : pids);
    if (sql_int(db, q) == 0) {
      if (sql_int(db, "SELECT count(*) FROM jobs WHERE state!='done'") == 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    kill(victim, SIGKILL);
    EXPECT_EQ(wait_child(victim, 10), 128 + SIGKILL);
    ++kills;
    if (sup_turn) {
      // Its workers must go with it (they would otherwise run beside the restarted supervisor's).
      ++storm.supervisor_kills;
      const auto t1 = std::chrono::steady_clock::now();
      auto alive = [&] { return std::count_if(watched.begin(), watched.end(), process_alive); };
      while (alive() > 0 && std::chrono::steady_clock::now() - t1 < std::chrono::seconds(5))
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      storm.orphans += static_cast<int>(alive());
      for (pid_t w : watched)
        if (process_alive(w)) kill(w, SIGKILL);  // do not leave them behind the test
      workers[1] = start_cli(sup_args, d.path / "sup.log");
    } else {
      ++storm.worker_kills;
      workers[0] = start_cli(work_args, d.path / "w0.log");
    }
  }
  EXPECT_GE(kills, min_kills) << "the victims were never caught mid-job often enough";
  if (with_supervisor) {
    EXPECT_GE(storm.supervisor_kills, min_kills / 2) << "the supervisor was never caught";
  }
  EXPECT_EQ(storm.orphans, 0) << "workers outlived their SIGKILLed supervisor";
  for (pid_t w : workers) EXPECT_EQ(wait_child(w, 200), 0);
  ::testing::Test::RecordProperty("sigkills", kills);
  std::printf(
      "crash campaign: %lld jobs, %d SIGKILLs mid-job (%d of a worker, %d of a supervisor, %d "
      "worker(s) outlived it), all workers finished\n",
      static_cast<long long>(total), kills, storm.worker_kills, storm.supervisor_kills, storm.orphans);

  // Every job done exactly once.
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs"), total);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), total);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='done'"), total);
  EXPECT_EQ(sql_int(db,
                    "SELECT count(*) FROM (SELECT job_id FROM attempts WHERE outcome='done' GROUP BY job_id "
                    "HAVING count(*) > 1) AS twice"),
            0);
  // Each kill of a worker left one lost attempt, reclaimed by a surviving worker (more only if a
  // starved heartbeat let a lease lapse, then fenced out); the workers of a killed supervisor got
  // SIGTERM and released their leases (or finished the job first).
  EXPECT_GE(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='lost'"), storm.worker_kills);
  std::printf("attempts lost %lld, released %lld\n",
              static_cast<long long>(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='lost'")),
              static_cast<long long>(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='released'")));
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='running'"), 0);
  // Results: one row per drop, none duplicated, with the swept parameters and the metrics.
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results"), with_results);
  EXPECT_EQ(sql_int(db, "SELECT count(DISTINCT job_id) FROM results"), with_results);
  for (const auto& col : param_columns)
    EXPECT_EQ(sql_int(db, fmt::format("SELECT count(*) FROM results WHERE \"{}\" IS NULL", col)), 0) << col;
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results WHERE trace_path NOT IN (SELECT output_path FROM jobs)"), 0);
  // Every output exists with its recorded size and checksum; nothing else is on disk.
  std::set<std::string> referenced;
  {
    db::Statement st(db, "SELECT output_path, output_sha256, output_bytes FROM jobs");
    while (st.step()) {
      const fs::path p = store.root() / st.get_text(0);
      referenced.insert(fs::weakly_canonical(p).string());
      ASSERT_TRUE(fs::exists(p)) << "missing output " << p;
      EXPECT_EQ(fs::file_size(p), static_cast<std::uintmax_t>(st.get_int(2)));
      EXPECT_EQ(queue::sha256_file(p), st.get_text(1)) << p;
    }
  }
  std::vector<std::string> orphans;
  for (const auto& e : fs::recursive_directory_iterator(store.root()))
    if (e.is_regular_file() && e.path().filename() != "gravsweep-campaign.json" &&  // the root's marker
        !referenced.count(fs::weakly_canonical(e.path()).string()))
      orphans.push_back(e.path().string());
  EXPECT_TRUE(orphans.empty()) << orphans.size() << " orphaned file(s), first " << orphans.front();
  if (store_kind == Store::sqlite) {
    EXPECT_EQ(sql_text(db, "PRAGMA integrity_check"), "ok");
  }
  // status after the storm: all done, no stale lease; resume finds nothing to repair.
  r = run_cli({"status", "--db", store.location}, d.path);
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find(fmt::format("{} done, 0 dead, 0 running, 0 to run", total)), std::string::npos) << r.out;
  r = run_cli(cat({"resume", "--dry-run"}, store.args()), d.path);
  EXPECT_NE(r.out.find("orphaned files found: 0"), std::string::npos) << r.out;
}

}  // namespace

struct CrashCampaign : ::testing::TestWithParam<Store> {};

TEST_P(CrashCampaign, SigkilledWorkersAndSupervisorsLoseNothingAndDuplicateNothing) {
  json doc = {{"sweep", "crash"},
              {"max_attempts", 6},
              {"base", json::parse(tiny_base())},
              {"axes",
               {{{"name", "gravity_m_s2"}, {"pointer", "/gravity_m_s2"}, {"values", {9.81, 3.71}}},
                {{"name", "bed_seed"}, {"pointer", "/bed/seed"}, {"values", {7, 8}}},
                {{"name", "impact_speed_m_s"},
                 {"pointer", "/projectile/impact_speed_m_s"},
                 {"range", {{"start", 0.4}, {"stop", 1.0}, {"step", 0.1}}}}}},
              {"repeats", {{"name", "projectile_seed"}, {"pointer", "/projectile/seed"}, {"count", 2}, {"start", 1}}}};
  // 4 beds (gravity x bed seed) and 56 drops (7 speeds x 2 projectile seeds per bed).
  EXPECT_NO_FATAL_FAILURE(crash_campaign(
      GetParam(), doc, 60, 56, {"gravity_m_s2", "bed_seed", "impact_speed_m_s", "projectile_seed", "bed_job_id"}, 4, 6,
      /*with_supervisor=*/true));
}

TEST_P(CrashCampaign, NoopJobsSurviveSigkillToo) {
  // The queue alone (no engine): 30 half-second jobs.
  json doc = {
      {"sweep", "crash_noop"},
      {"job", "noop"},
      {"max_attempts", 6},
      {"base", {{"g", 1.5}, {"sleep_s", 0.5}}},
      {"axes",
       {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"range", {{"start", 0.1}, {"stop", 3.0}, {"step", 0.1}}}}}}};
  EXPECT_NO_FATAL_FAILURE(
      crash_campaign(GetParam(), doc, 30, 30, {"gravity_m_s2", "noop_value"}, 4, 4, /*with_supervisor=*/true));
}

TEST_P(CrashCampaign, SigkilledSupervisorTakesItsWorkersDownAndLosesNothing) {
  // 3 SIGKILLs of `work --workers 3` mid-campaign: its workers must exit (they would otherwise
  // pile up beside the restarted supervisor's), and the campaign still ends with every job done once.
  TempDir d;
  const CampaignStore store(GetParam(), d.path);
  if (!store.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << store.skip;
  json doc = {
      {"sweep", "sup"},
      {"job", "noop"},
      {"max_attempts", 6},
      {"base", {{"g", 1.0}, {"sleep_s", 0.3}}},
      {"axes",
       {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"range", {{"start", 0.1}, {"stop", 4.0}, {"step", 0.1}}}}}}};
  write_text(d.path / "spec.json", doc.dump());
  ASSERT_EQ(run_cli(cat({"submit", "spec.json"}, store.args()), d.path).code, 0);
  const std::string db_path = store.location;
  const std::vector<std::string> args = cat({"work", "--workers", "3", "--threads", "1", "--lease", "2", "--heartbeat",
                                             "0.3", "--poll", "0.1", "--backoff", "0.1", "--quiet"},
                                            store.args());
  db::Database db(db_path);
  int orphans_left = 0;
  for (int kill_no = 0; kill_no < 3; ++kill_no) {
    const pid_t sup = start_cli(args, d.path / "work.log");
    const auto t0 = std::chrono::steady_clock::now();
    while (sql_int(db, "SELECT count(DISTINCT pid) FROM attempts WHERE outcome='running'") < 3 &&
           std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20))
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::vector<pid_t> workers;
    {
      db::Statement st(db, "SELECT DISTINCT pid FROM attempts WHERE outcome='running'");
      while (st.step()) workers.push_back(static_cast<pid_t>(st.get_int(0)));
    }
    ASSERT_FALSE(workers.empty());
    kill(sup, SIGKILL);
    EXPECT_EQ(wait_child(sup, 10), 128 + SIGKILL);
    const auto t1 = std::chrono::steady_clock::now();
    auto alive = [&] { return std::count_if(workers.begin(), workers.end(), process_alive); };
    while (alive() > 0 && std::chrono::steady_clock::now() - t1 < std::chrono::seconds(5))
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    orphans_left += static_cast<int>(alive());
    for (pid_t w : workers)
      if (process_alive(w)) kill(w, SIGKILL);  // do not leave them behind the test
  }
  std::printf("supervisor SIGKILLed 3 times: %d worker(s) outlived it by 5 s\n", orphans_left);
  EXPECT_EQ(orphans_left, 0) << "workers outlived their supervisor";
  const auto r =
      run_cli(cat({"work", "--workers", "2", "--quiet", "--lease", "2", "--poll", "0.1"}, store.args()), d.path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), 40);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='done'"), 40);
  db::Statement st(db, "SELECT output_path, output_sha256 FROM jobs");
  while (st.step()) {
    const fs::path p = store.root() / st.get_text(0);
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_EQ(queue::sha256_file(p), st.get_text(1));
  }
}

GRAVSWEEP_INSTANTIATE_ON_THE_QUEUE_BACKEND(CrashCampaign);

// A PostgreSQL campaign through the CLI, on a throwaway server (tests/common/postgres_server.h):
// 8 worker processes on 200 no-op jobs, each job done exactly once; --files is required.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "campaign_store.h"
#include "db/database.h"
#include "scheduler/queue/canonical.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
using nlohmann::json;
namespace fs = std::filesystem;

TEST(PostgresCampaign, EightWorkersDoTwoHundredJobsEachExactlyOnce) {
  TempDir d;
  const CampaignStore store(Store::postgres, d.path);
  if (!store.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << store.skip;
  json doc = {{"sweep", "pg200"},
              {"job", "noop"},
              {"base", {{"i", 0}, {"sleep_s", 0.0}}},
              {"axes", {{{"name", "i"}, {"pointer", "/i"}, {"range", {{"start", 0}, {"stop", 199}, {"step", 1}}}}}}};
  write_text(d.path / "spec.json", doc.dump());
  std::vector<std::string> submit = {"submit", "spec.json", "--db", store.location, "--files", store.files.string()};
  auto r = run_cli(submit, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("200 new, 0 already present"), std::string::npos) << r.out;
  r = run_cli(submit, d.path);
  EXPECT_NE(r.out.find("0 new, 200 already present"), std::string::npos) << r.out;

  r = run_cli({"work", "--db", store.location, "--files", store.files.string(), "--workers", "8", "--threads", "1",
               "--poll", "0.05", "--quiet"},
              d.path);
  ASSERT_EQ(r.code, 0) << r.err;

  db::Database db(store.location);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), 200);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts"), 200) << "a job was claimed twice";
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='done'"), 200);
  EXPECT_EQ(sql_int(db, "SELECT count(DISTINCT job_id) FROM attempts WHERE outcome='done'"), 200);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results"), 200);
  EXPECT_EQ(sql_int(db, "SELECT count(DISTINCT job_id) FROM results"), 200);
  EXPECT_EQ(sql_int(db, "SELECT count(DISTINCT worker) FROM attempts"), 8) << "every worker should have claimed";
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results WHERE i IS NULL OR noop_value IS NULL"), 0);
  db::Statement st(db, "SELECT output_path, output_sha256 FROM jobs");
  int files = 0;
  while (st.step()) {
    const fs::path p = store.files / st.get_text(0);
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_EQ(queue::sha256_file(p), st.get_text(1));
    ++files;
  }
  EXPECT_EQ(files, 200);
  r = run_cli({"status", "--db", store.location}, d.path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("200 done, 0 dead, 0 running, 0 to run"), std::string::npos) << r.out;
}

TEST(PostgresCampaign, AServerCampaignNeedsItsFilesRoot) {
  TempDir d;
  const CampaignStore store(Store::postgres, d.path);
  if (!store.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << store.skip;
  write_text(d.path / "spec.json", two_noop_jobs_spec());
  const auto r = run_cli({"submit", "spec.json", "--db", store.location}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--files"), std::string::npos) << r.err;
  // Not a campaign yet: work refuses it, naming the server.
  const auto w = run_cli({"work", "--db", store.location, "--files", store.files.string()}, d.path);
  EXPECT_EQ(w.code, 2);
  EXPECT_NE(w.err.find("not a gravsweep campaign"), std::string::npos) << w.err;
}

namespace {

/// Rows of `sql` as text, one line per row (the same on both sides of a round trip).
std::string dump(db::Database& db, const std::string& sql) {
  db::Statement st(db, sql);
  std::string out;
  while (st.step()) {
    for (int i = 0; i < st.columns(); ++i) out += (i ? "|" : "") + (st.is_null(i) ? "NULL" : st.get_text(i));
    out += "\n";
  }
  return out;
}

}  // namespace

TEST(PostgresCampaign, CopyRoundTripSqliteToPostgresAndBackKeepsEverything) {
  TempDir d;
  const CampaignStore pg(Store::postgres, d.path, "pg");
  if (!pg.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << pg.skip;
  json doc = {{"sweep", "cp"},
              {"job", "noop"},
              {"base", {{"g", 1.5}, {"value", 2.5}}},
              {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {1.0, 1.5, 2.0, 2.5, 3.0, 3.5}}}}}};
  write_text(d.path / "spec.json", doc.dump());
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "a.db"}, d.path).code, 0);
  auto r = run_cli({"work", "--db", "a.db", "--max-jobs", "4", "--quiet"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;

  r = run_cli({"campaign", "copy", "a.db", pg.location, "--files", pg.files.string()}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("6 jobs, 4 attempts, 4 results rows"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("4 files copied"), std::string::npos) << r.out;
  r = run_cli({"campaign", "copy", pg.location, "b.db", "--from-files", pg.files.string()}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  // A second copy into a campaign that exists is refused.
  r = run_cli({"campaign", "copy", "a.db", pg.location, "--files", pg.files.string()}, d.path);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.err.find("already holds a campaign"), std::string::npos) << r.err;

  db::Database a((d.path / "a.db").string()), b((d.path / "b.db").string()), p(pg.location);
  const std::vector<std::string> queries = {
      "SELECT job_id, kind, sweep_id, state, priority, deps_pending, attempts, max_attempts, lease_token, "
      "output_path, output_sha256, output_bytes, params_json, scenario_json, created_at, finished_at FROM jobs "
      "ORDER BY job_id",
      "SELECT job_id, attempt, lease_token, kind, worker, outcome, started_at, ended_at, output_path, report_json "
      "FROM attempts ORDER BY job_id, attempt",
      "SELECT * FROM results ORDER BY job_id",
      "SELECT name, role, sql_type, position FROM results_columns ORDER BY position",
      "SELECT sweep_id, job_id, shared FROM sweep_jobs ORDER BY job_id"};
  for (const auto& q : queries) {
    const std::string before = dump(a, q);
    EXPECT_FALSE(before.empty()) << q;
    EXPECT_EQ(dump(b, q), before) << q;
    EXPECT_EQ(dump(p, "SELECT count(*) FROM (" + q + ") AS x"), dump(a, "SELECT count(*) FROM (" + q + ") AS x"));
  }
  EXPECT_EQ(dump(p, "SELECT job_id, state, output_sha256 FROM jobs ORDER BY job_id"),
            dump(a, "SELECT job_id, state, output_sha256 FROM jobs ORDER BY job_id"));
  // The campaign goes on on the server: the 2 jobs left run there, with their files in --files.
  r = run_cli({"work", "--db", pg.location, "--files", pg.files.string(), "--workers", "2", "--quiet"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql_int(p, "SELECT count(*) FROM jobs WHERE state='done'"), 6);
  EXPECT_EQ(sql_int(p, "SELECT count(*) FROM results"), 6);
  EXPECT_EQ(sql_int(p, "SELECT max(attempt_id) FROM attempts"), 6) << "keys continue after the copied ones";
  EXPECT_EQ(std::distance(fs::directory_iterator(pg.files / "noop"), fs::directory_iterator()), 6);
}

TEST(PostgresCampaign, SlurmSubmitDryRunPrintsOneArrayOfPilotWorkers) {
  TempDir d;
  const CampaignStore store(Store::postgres, d.path);
  if (!store.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << store.skip;
  write_text(d.path / "spec.json", two_noop_jobs_spec());
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", store.location, "--files", store.files.string()}, d.path).code, 0);
  auto r = run_cli({"slurm", "submit", "--db", store.location, "--files", store.files.string(), "--workers", "3",
                    "--threads", "2", "--partition", "debug", "--time", "00:10:00", "--dry-run"},
                   d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const std::string& line : {std::string("#SBATCH --array=1-3\n"), std::string("#SBATCH --cpus-per-task=2\n"),
                                  std::string("#SBATCH --partition=debug\n"), std::string("#SBATCH --time=00:10:00\n"),
                                  "#SBATCH --output=\"" + (store.files / "slurm").string() + "/%A_%a.log\"\n",
                                  " work --db '" + store.location + "' --files '" + store.files.string() +
                                      "' --threads 2 --lease 60 --checkpoint-interval 300\n"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << " not in:\n" << r.out;
  EXPECT_FALSE(fs::exists(store.files / "slurm")) << "a dry run submits and writes nothing";
  // An SQLite campaign is refused: its file must not be shared between nodes.
  // (lite.db: c.files beside c.db is the server campaign's files root, marked as its own)
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "lite.db"}, d.path).code, 0);
  r = run_cli({"slurm", "submit", "--db", "lite.db", "--dry-run"}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("PostgreSQL"), std::string::npos) << r.err;
}

TEST(PostgresCampaign, SlurmSubmitRefusesOptionsOutsideSlurmSyntaxAndQuotesEveryPath) {
  TempDir d;
  const CampaignStore store(Store::postgres, d.path);
  if (!store.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << store.skip;
  const fs::path root = d.path / "my files";  // a space: must not cut the #SBATCH --output line
  write_text(d.path / "spec.json", two_noop_jobs_spec());
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", store.location, "--files", root.string()}, d.path).code, 0);
  const auto slurm = [&](const std::string& option, const std::string& value) {
    return run_cli({"slurm", "submit", "--db", store.location, "--files", root.string(), option, value, "--dry-run"},
                   d.path);
  };
  struct Bad {
    const char *option, *value;
  };
  for (const Bad& b : {Bad{"--time", "00:10:00\n#SBATCH --wrap=id"}, Bad{"--time", "10 minutes"},
                       Bad{"--time", "1:2:3:4"}, Bad{"--partition", "debug\nrm -rf ~"}, Bad{"--partition", "a b"},
                       Bad{"--account", "proj;id"}, Bad{"--account", "a\n#SBATCH --uid=0"}}) {
    const auto r = slurm(b.option, b.value);
    EXPECT_EQ(r.code, 2) << b.option << " " << b.value << ":\n" << r.out << r.err;
    EXPECT_NE(r.err.find(b.option), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("#SBATCH"), std::string::npos) << r.out;
  }
  for (const char* t : {"30", "30:00", "04:00:00", "2-0", "2-12:00", "1-00:30:00", "UNLIMITED"})
    EXPECT_EQ(slurm("--time", t).code, 0) << t;
  EXPECT_EQ(slurm("--partition", "debug,long").code, 0);
  const auto r = slurm("--account", "proj_1.a-b");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("#SBATCH --account=proj_1.a-b\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("#SBATCH --output=\"" + (root / "slurm").string() + "/%A_%a.log\"\n"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find(" --files '" + root.string() + "' "), std::string::npos) << r.out;
}

// The server restarted (fast, then immediate) and stopped for a few seconds while four workers
// run: the workers reconnect with backoff and go on; every job is done exactly once and no worker
// exits (before, "server closed the connection unexpectedly", exit 1, jobs left running).
TEST(PostgresCampaign, WorkersRideOutServerRestartsAndAnOutage) {
  TempDir d;
  std::string why;
  PostgresServer* server = PostgresServer::shared(why);
  if (!server) GTEST_SKIP() << "PostgreSQL not available: " << why;
  const std::string url = server->create_database();
  const fs::path root = d.path / "files";
  constexpr int kJobs = 80;  // 10 s of work on 4 workers: longer than the restarts and the outage
  json doc = {{"sweep", "restart"},
              {"job", "noop"},
              {"base", {{"i", 0}, {"sleep_s", 0.5}}},
              {"axes", {{{"name", "i"}, {"pointer", "/i"}, {"range", {{"start", 1}, {"stop", kJobs}, {"step", 1}}}}}}};
  write_text(d.path / "spec.json", doc.dump());
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", url, "--files", root.string()}, d.path).code, 0);
  const fs::path log = d.path / "work.log";
  const pid_t work = start_cli({"work", "--db", url, "--files", root.string(), "--workers", "4", "--threads", "1",
                                "--lease", "30", "--poll", "0.05", "--db-outage", "60"},
                               log);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  EXPECT_EQ(server->restart("fast"), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  EXPECT_EQ(server->restart("immediate"), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  EXPECT_EQ(server->stop("fast"), 0);
  std::this_thread::sleep_for(std::chrono::seconds(4));
  EXPECT_EQ(server->start_again(), 0);
  const int code = wait_child(work, 240);
  std::ifstream in(log);
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  EXPECT_EQ(code, 0) << text.substr(text.size() > 3000 ? text.size() - 3000 : 0);
  EXPECT_EQ(text.find("exited with code"), std::string::npos) << "a worker exited";
  EXPECT_NE(text.find("reconnected to the database"), std::string::npos) << "the outage was not noticed";
  db::Database db(url);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), kJobs);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='done'"), kJobs) << "a job was done twice";
  EXPECT_EQ(sql_int(db, "SELECT count(DISTINCT job_id) FROM results"), kJobs);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='running'"), 0);
  db::Statement st(db, "SELECT output_path, output_sha256 FROM jobs");
  while (st.step()) EXPECT_EQ(queue::sha256_file(root / st.get_text(0)), st.get_text(1)) << st.get_text(0);
}

// The verbs as users run them, as real processes on real files: submit (idempotent, extension,
// malformed spec), work (exit codes, SIGTERM releases the lease), status, resume, results.
#include <gtest/gtest.h>

#include <csignal>
#include <nlohmann/json.hpp>
#include <thread>

#include "db/database.h"
#include "scheduler/pipeline/impact_runners.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
using nlohmann::json;

namespace {

std::string noop_spec(const std::vector<double>& gs, double sleep_s = 0.0, int fail_attempts = 0,
                      int max_attempts = 3) {
  json doc = {{"sweep", "cli"},
              {"job", "noop"},
              {"max_attempts", max_attempts},
              {"base", {{"g", 1.5}, {"sleep_s", sleep_s}, {"fail_attempts", fail_attempts}}},
              {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", gs}}}}};
  return doc.dump(2);
}

}  // namespace

TEST(CliQueue, SubmitIsIdempotentAndExtensionAddsOnlyNewJobs) {
  TempDir d;
  write_text(d.path / "spec.json", noop_spec({0.5, 1.62, 9.81}));
  auto r = run_cli({"submit", "spec.json", "--db", "c.db"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("3 new, 0 already present"), std::string::npos) << r.out;
  r = run_cli({"submit", "spec.json", "--db", "c.db"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("0 new, 3 already present"), std::string::npos) << r.out;
  write_text(d.path / "spec.json", noop_spec({0.5, 1.62, 9.81, 3.71}));
  r = run_cli({"submit", "spec.json", "--db", "c.db"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("1 new, 3 already present"), std::string::npos) << r.out;
  db::Database db((d.path / "c.db").string());
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs"), 4);
}

TEST(CliQueue, MalformedSpecIsRefusedAndNothingIsWritten) {
  TempDir d;
  json doc = json::parse(noop_spec({0.5, 1.62}));
  doc["axes"][0]["values"][1] = "fast";
  write_text(d.path / "bad.json", doc.dump(2));
  auto r = run_cli({"submit", "bad.json", "--db", "c.db"}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/axes/0/values/1: found \"fast\" (string), expected a number"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(d.path / "c.db")) << "a refused spec must not create the database";
  // Into an existing campaign: still nothing written.
  write_text(d.path / "good.json", noop_spec({0.5}));
  ASSERT_EQ(run_cli({"submit", "good.json", "--db", "c.db"}, d.path).code, 0);
  r = run_cli({"submit", "good.json", "bad.json", "--db", "c.db"}, d.path);
  EXPECT_EQ(r.code, 2);
  db::Database db((d.path / "c.db").string());
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs"), 1);
  EXPECT_EQ(sql_int(db, "SELECT submits FROM sweeps"), 1);
}

TEST(CliQueue, WorkersRunEverythingRetryAndReportDeadJobs) {
  TempDir d;
  // fail_attempts=1: every job fails once, then succeeds on its retry.
  write_text(d.path / "spec.json", noop_spec({0.5, 1.62, 9.81, 3.71, 2.0, 4.0}, 0.05, 1));
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, d.path).code, 0);
  auto r = run_cli({"work", "--db", "c.db", "--workers", "2", "--backoff", "0.05", "--poll", "0.02"}, d.path);
  EXPECT_EQ(r.code, 0) << r.err;
  db::Database db((d.path / "c.db").string());
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), 6);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM attempts WHERE outcome='failed'"), 6);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results"), 6);
  EXPECT_EQ(sql_int(db, "SELECT count(DISTINCT pid) FROM attempts"), 2) << "two worker processes";
  // Every result's file exists with its recorded checksum size.
  db::Statement st(db, "SELECT trace_path, trace_bytes FROM results");
  while (st.step())
    EXPECT_EQ(std::filesystem::file_size(campaign_file(d.path, "c", st.get_text(0))),
              static_cast<std::uintmax_t>(st.get_int(1)));
  // A job that always fails goes dead after max_attempts; work exits 4.
  write_text(d.path / "dead.json", noop_spec({7.0}, 0.0, 99, 2));
  ASSERT_EQ(run_cli({"submit", "dead.json", "--db", "c.db"}, d.path).code, 0);
  r = run_cli({"work", "--db", "c.db", "--backoff", "0.01", "--poll", "0.02"}, d.path);
  EXPECT_EQ(r.code, 4) << r.err;
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='dead' AND attempts=2"), 1);
  r = run_cli({"status", "--db", "c.db"}, d.path);
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("asked to fail"), std::string::npos) << r.out;
  // results: filter, csv, json
  r = run_cli({"results", "--db", "c.db", "--where", "gravity_m_s2<2", "--format", "csv", "--columns",
               "gravity_m_s2,noop_value", "--sort", "gravity_m_s2"},
              d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "gravity_m_s2,noop_value\r\n0.5,0\r\n1.62,0\r\n");
  r = run_cli({"results", "--db", "c.db", "--where", "gravity_m_s2=4", "--format", "json"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const json rows = json::parse(r.out);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0]["gravity_m_s2"], 4.0);
  EXPECT_EQ(rows[0]["trace_sha256"].get<std::string>().size(), 64u);
  // The default table: the job and the swept parameters (no paper metrics in no-op jobs); --all
  // shows every column.
  r = run_cli({"results", "--db", "c.db"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string header = r.out.substr(0, r.out.find('\n'));
  EXPECT_NE(header.find("job_id"), std::string::npos) << r.out;
  EXPECT_NE(header.find("gravity_m_s2"), std::string::npos) << r.out;
  EXPECT_EQ(header.find("trace_sha256"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("more columns: --all"), std::string::npos) << r.out;
  r = run_cli({"results", "--db", "c.db", "--all"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.substr(0, r.out.find('\n')).find("trace_sha256"), std::string::npos) << r.out;
  r = run_cli({"results", "--db", "c.db", "--where", "gravity_m_s2<1; DELETE FROM jobs"}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("expected 'and'"), std::string::npos) << r.err;
}

TEST(CliQueue, SigtermEndsTheJobAndReleasesItsLease) {
  TempDir d;
  write_text(d.path / "spec.json", noop_spec({1.0}, 30.0));
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, d.path).code, 0);
  const pid_t w = start_cli({"work", "--db", (d.path / "c.db").string(), "--lease", "60"}, d.path / "w.log");
  db::Database db((d.path / "c.db").string());
  const auto t0 = std::chrono::steady_clock::now();
  while (sql_int(db, "SELECT count(*) FROM jobs WHERE state='running' AND progress > 0") == 0) {
    ASSERT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(20)) << "job never started";
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(w, SIGTERM);
  // The no-op job sleeps 30 s: a worker that ends within wait_child's 10 s did not wait it out.
  EXPECT_EQ(wait_child(w, 10), 130);
  EXPECT_EQ(sql_text(db, "SELECT state FROM jobs"), "queued");
  EXPECT_EQ(sql_int(db, "SELECT attempts FROM jobs"), 0);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE lease_owner IS NOT NULL"), 0);
  EXPECT_EQ(sql_text(db, "SELECT outcome FROM attempts"), "released");
  // Nothing left behind in tmp/.
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(d.path / "c.files" / "tmp")) ++files;
  EXPECT_EQ(files, 0u);
}

TEST(CliQueue, ImpactSweepSharesBedsAndExtendsIdempotently) {
  TempDir d;
  const std::string example = std::string(GRAVSWEEP_SOURCE_DIR) + "/examples/sweep_tiny.json";
  auto r = run_cli({"submit", example, "--db", "c.db"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("14 jobs planned (2 bed, 12 drop): 14 new, 0 already present"), std::string::npos) << r.out;
  r = run_cli({"submit", example, "--db", "c.db"}, d.path);
  EXPECT_NE(r.out.find("0 new, 14 already present"), std::string::npos) << r.out;
  // One more impact speed: 4 new drops (2 gravities x 2 seeds) on the 2 existing beds.
  json doc = json::parse(std::ifstream(example));
  doc["axes"][1]["values"].push_back(1.3);
  write_text(d.path / "more.json", doc.dump());
  r = run_cli({"submit", "more.json", "--db", "c.db"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("18 jobs planned (2 bed, 16 drop): 4 new, 14 already present"), std::string::npos) << r.out;
  db::Database db((d.path / "c.db").string());
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM job_deps"), 16);
  EXPECT_EQ(sql_int(db, "SELECT count(DISTINCT dep_id) FROM job_deps"), 2);
  // A field the scenario does not have is refused with its pointer; nothing is written.
  doc["axes"][1]["pointer"] = "/projectile/speed_m_s";
  write_text(d.path / "typo.json", doc.dump());
  r = run_cli({"submit", "typo.json", "--db", "c.db"}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/axes/1/pointer: found \"/projectile/speed_m_s\" (string), expected a pointer to a field "
                       "present in the base scenario"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs"), 18);
}

TEST(CliQueue, SubmitWhereTakesPartOfASweepWithOnlyTheBedsItNeeds) {
  TempDir d;
  const std::string example = std::string(GRAVSWEEP_SOURCE_DIR) + "/examples/sweep_tiny.json";
  // The second repeat at 1 g only: 3 speeds, on the one 1 g bed.
  auto r = run_cli({"submit", example, "--db", "c.db", "--where", "projectile_seed>=2", "--where", "gravity_m_s2>5"},
                   d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("--where leaves out 9 of 12 points"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("4 jobs planned (1 bed, 3 drop): 4 new"), std::string::npos) << r.out;
  {
    db::Database db((d.path / "c.db").string());
    EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE kind='drop' AND params_json LIKE '%\"projectile_seed\":2%'"),
              3);
  }
  // The whole sweep later adds the rest and keeps what is there.
  r = run_cli({"submit", example, "--db", "c.db"}, d.path);
  EXPECT_NE(r.out.find("14 jobs planned (2 bed, 12 drop): 10 new, 4 already present"), std::string::npos) << r.out;
  // A column that is not an axis is refused (exit 2) naming the axis columns; nothing is written.
  r = run_cli({"submit", example, "--db", "d.db", "--where", "seed=2"}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("found column 'seed', expected one of: gravity_m_s2, impact_speed_m_s, projectile_seed"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(d.path / "d.db"));
}

TEST(CliQueue, FollowingWorkersPickUpLateSubmissionsAndTheSupervisorForwardsSigterm) {
  TempDir d;
  write_text(d.path / "a.json", noop_spec({1.0}, 0.05));
  ASSERT_EQ(run_cli({"submit", "a.json", "--db", "c.db"}, d.path).code, 0);
  const pid_t sup =
      start_cli({"work", "--db", (d.path / "c.db").string(), "--workers", "2", "--follow", "--poll", "0.05", "--quiet"},
                d.path / "w.log");
  db::Database db((d.path / "c.db").string());
  auto wait_done = [&](std::int64_t n) {
    const auto t0 = std::chrono::steady_clock::now();
    while (sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'") < n) {
      if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(20)) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return true;
  };
  ASSERT_TRUE(wait_done(1));
  // The workers are idle but still there; new jobs are picked up.
  write_text(d.path / "b.json", noop_spec({1.0, 2.0, 3.0}, 0.05));
  ASSERT_EQ(run_cli({"submit", "b.json", "--db", "c.db"}, d.path).code, 0);
  ASSERT_TRUE(wait_done(3));
  EXPECT_EQ(waitpid(sup, nullptr, WNOHANG), 0) << "--follow workers must not exit when the queue is empty";
  kill(sup, SIGTERM);
  EXPECT_EQ(wait_child(sup, 10), 130);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='running'"), 0);
}

TEST(CliQueue, ResumeAfterEveryWorkerWasKilled) {
  TempDir d;
  write_text(d.path / "spec.json", noop_spec({1.0, 2.0}, 1.0));
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, d.path).code, 0);
  const std::string db_path = (d.path / "c.db").string();
  const pid_t w = start_cli({"work", "--db", db_path, "--lease", "1", "--heartbeat", "0.2"}, d.path / "w.log");
  db::Database db(db_path);
  const auto t0 = std::chrono::steady_clock::now();
  while (sql_int(db, "SELECT count(*) FROM jobs WHERE state='running' AND progress > 0.1") == 0) {
    ASSERT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(20));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(w, SIGKILL);
  EXPECT_EQ(wait_child(w, 5), 128 + SIGKILL);
  // A file the dead worker left behind, as if it died between its rename and its commit.
  const std::string planned = sql_text(db, "SELECT output_path FROM attempts WHERE outcome='running'");
  ASSERT_FALSE(planned.empty());
  write_text(campaign_file(d.path, "c", planned), "half");
  auto r = run_cli({"status", "--db", "c.db"}, d.path);
  EXPECT_NE(r.out.find("running jobs (1 active, 0 stale leases)"), std::string::npos) << r.out;
  std::this_thread::sleep_for(std::chrono::milliseconds(1200));
  r = run_cli({"status", "--db", "c.db"}, d.path);
  EXPECT_NE(r.out.find("1 stale lease(s)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("STALE"), std::string::npos) << r.out;
  r = run_cli({"resume", "--db", "c.db"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("expired leases: 1 requeued"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(campaign_file(d.path, "c", planned))) << "the lost attempt's file must go";
  EXPECT_EQ(sql_text(db, "SELECT outcome FROM attempts WHERE output_path='" + planned + "'"), "lost");
  r = run_cli({"work", "--db", "c.db", "--quiet"}, d.path);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), 2);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results"), 2);
  EXPECT_EQ(sql_text(db, "PRAGMA integrity_check"), "ok");
}

// The verbs that read a campaign mean the same on both backends: run once on an SQLite file and
// once on the throwaway PostgreSQL server (tests/common/postgres_server.h).
// - `--where` is typed by the column: `~` (contains) works on both, a value that is not a number
//   against a numeric column is refused (exit 2, naming the column and the value), nan too;
// - every verb that reads a campaign takes a postgresql:// URL: export, plot results, model, report.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "campaign_store.h"
#include "db/database.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

struct BackendVerbs : StoreTest {
  /// `verb...` followed by --db LOCATION [--files DIR] and `more`.
  CmdResult cli(std::vector<std::string> args, const std::vector<std::string>& more = {}) {
    for (const auto& a : store.args()) args.push_back(a);
    args.insert(args.end(), more.begin(), more.end());
    return run_cli(args, dir.path);
  }
  /// The same for a verb that reads the database only (results, plot results): --db LOCATION.
  CmdResult db_only(std::vector<std::string> args, const std::vector<std::string>& more = {}) {
    args.insert(args.end(), {"--db", store.location});
    args.insert(args.end(), more.begin(), more.end());
    return run_cli(args, dir.path);
  }
  /// `verb...` reading the campaign as its input argument (model, report): LOCATION [--files DIR].
  CmdResult read_input(std::vector<std::string> args, const std::vector<std::string>& more = {}) {
    args.push_back(store.location);
    if (!store.files.empty()) args.insert(args.end(), {"--files", store.files.string()});
    args.insert(args.end(), more.begin(), more.end());
    return run_cli(args, dir.path);
  }
  std::size_t lines(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }
};

}  // namespace

TEST_P(BackendVerbs, WhereIsTypedTheSameOnBothBackends) {
  json doc = {{"sweep", "w"},
              {"job", "noop"},
              {"base", {{"g", 1.0}, {"sleep_s", 0.0}}},
              {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {0.5, 1.0, 1.5, 2.0}}}}}};
  write_text(dir.path / "spec.json", doc.dump());
  ASSERT_EQ(cli({"submit", "spec.json"}).code, 0);
  auto r = cli({"work", "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  r = db_only({"results", "--format", "csv"}, {"--where", "gravity_m_s2<1.2"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(lines(r.out), 3u) << r.out;
  // `~` (contains) on a text column and on a numeric one.
  std::string job;
  {
    db::Database db(store.location);
    job = sql_text(db, "SELECT job_id FROM results ORDER BY job_id LIMIT 1");
  }
  r = db_only({"results", "--format", "csv"}, {"--where", "job_id~" + job.substr(0, 12)});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(lines(r.out), 2u) << r.out;
  EXPECT_NE(r.out.find(job), std::string::npos) << r.out;
  r = db_only({"results", "--format", "csv"}, {"--where", "gravity_m_s2~0.5"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(lines(r.out), 2u) << r.out;
  // A text column compares with the text as typed, also when it looks like a number.
  r = db_only({"results", "--format", "csv"}, {"--where", "sweep=w"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(lines(r.out), 5u) << r.out;
  // Not a number against a numeric column, and nan: refused, naming the column and the value.
  for (const std::string bad : {"gravity_m_s2<abc", "gravity_m_s2<'1'"}) {
    r = db_only({"results"}, {"--where", bad});
    EXPECT_EQ(r.code, 2) << bad << ": " << r.out << r.err;
    EXPECT_NE(r.err.find("gravity_m_s2"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("expected a number"), std::string::npos) << r.err;
  }
  EXPECT_NE(db_only({"results"}, {"--where", "gravity_m_s2<abc"}).err.find("'abc'"), std::string::npos);
  for (const std::string bad : {"gravity_m_s2<nan", "gravity_m_s2>=-inf", "runtime_s<1e999"}) {
    r = db_only({"results"}, {"--where", bad});
    EXPECT_EQ(r.code, 2) << bad << ": " << r.out << r.err;
    EXPECT_NE(r.err.find("finite number"), std::string::npos) << r.err;
  }
  // `submit --where` (the planned points, in memory) means the same.
  r = cli({"submit", "spec.json"}, {"--where", "gravity_m_s2<abc"});
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("expected a number"), std::string::npos) << r.err;
}

TEST_P(BackendVerbs, EveryVerbReadingACampaignTakesItsLocation) {
  write_text(dir.path / "spec.json", tiny_speed_sweep("v", {0.4, 0.5, 0.6, 0.7, 0.8, 0.9}));
  ASSERT_EQ(cli({"submit", "spec.json"}).code, 0);
  auto r = cli({"work", "--workers", "2", "--threads", "1", "--quiet"});
  ASSERT_EQ(r.code, 0) << r.err;
  r = cli({"export", "--out", "ds", "--rate-hz", "2000", "--allow-dirty"});  // this test's build may be dirty
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("6 drops exported"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir.path / "ds" / "trials.csv"));
  r = db_only({"plot", "results", "--x", "impact_speed_m_s", "--y", "zstop_m", "--out", "z.png"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir.path / "z.png"));
  r = read_input({"model", "fit"}, {"--model", "base", "--plot", "fall.png"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("6 trials"), std::string::npos) << r.err;
  r = read_input({"report"}, {"--out", "rep", "--folds", "3"});
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir.path / "rep")) << r.out;
}

GRAVSWEEP_INSTANTIATE_ON_THE_QUEUE_BACKEND(BackendVerbs);

#ifdef GRAVSWEEP_QUEUE_TESTS_ON_POSTGRES
TEST(BackendVerbs, AServerCampaignReadWithoutItsFilesRootIsRefused) {
  TempDir d;
  const CampaignStore store(Store::postgres, d.path);
  if (!store.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << store.skip;
  write_text(d.path / "spec.json", two_noop_jobs_spec());
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", store.location, "--files", store.files.string()}, d.path).code, 0);
  const auto r = run_cli({"model", "fit", store.location}, d.path);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("--files"), std::string::npos) << r.err;
}
#endif

// A gravity sweep feeds the model comparison directly: a real tiny campaign (`submit` +
// `work`, 2 gravities x 2 speeds x 2 repeats, 8 drops on 2 beds), then `model table3|rank`,
// `report`, `measurements import --where` and `from-runs` on it, `results --group-by` against
// means computed here, and a drop that cannot be measured listed with the reason.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <sys/wait.h>

#include "results/io/trace_file.h"
#include "results_helpers.h"
#include "tests/common/tiny_campaign.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using Cmd = gravsweep::testing::CliRun;
Cmd run(const std::string& args, bool merge_stderr = true) {
  return gravsweep::testing::run_gravsweep(args, merge_stderr);
}

/// 2 gravities x 2 speeds x 2 repeats of the tiny campaign scenario (tests/common/tiny_campaign.h).
std::string sweep_spec() {
  json doc = json::parse(R"({
    "sweep": "campaign_cli_test",
    "axes": [
      {"name": "gravity_m_s2", "pointer": "/gravity_m_s2", "values": [9.81, 3.71]},
      {"name": "impact_speed_m_s", "pointer": "/projectile/impact_speed_m_s", "values": [0.4, 0.6]}
    ],
    "repeats": {"name": "projectile_seed", "pointer": "/projectile/seed", "count": 2, "start": 1},
    "max_attempts": 1
  })");
  doc["base"] = json::parse(gravsweep::test::tiny_base());
  return doc.dump();
}

class CampaignCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new gravsweep::testing::TempDir;
    std::ofstream(dir_->path / "sweep.json") << sweep_spec();
    const Cmd s = run("submit '" + (dir_->path / "sweep.json").string() + "' --db '" + db() + "'");
    ASSERT_EQ(s.code, 0) << s.out;
    const Cmd w = run("work --db '" + db() + "' --workers 2 --threads 1");
    ASSERT_EQ(w.code, 0) << w.out;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static std::string db() { return (dir_->path / "c.db").string(); }
  static fs::path path() { return dir_->path; }
  static gravsweep::testing::TempDir* dir_;
};
gravsweep::testing::TempDir* CampaignCli::dir_ = nullptr;

}  // namespace

TEST_F(CampaignCli, ModelVerbsReadTheCampaignDatabaseAndSayWhatTheyRead) {
  const Cmd t3 = run("model table3 '" + db() + "'");
  ASSERT_EQ(t3.code, 0) << t3.out;
  EXPECT_NE(t3.out.find("campaign database (submit/work), 8 trials"), std::string::npos) << t3.out;
  EXPECT_NE(t3.out.find("3.71"), std::string::npos) << t3.out;
  const Cmd rk = run("model rank '" + db() + "'");
  ASSERT_EQ(rk.code, 0) << rk.out;
  EXPECT_NE(rk.out.find("Verdict:"), std::string::npos) << rk.out;
  const Cmd rp = run("report '" + db() + "' --out '" + (path() / "r").string() + "'");
  ASSERT_EQ(rp.code, 0) << rp.out;
  std::ifstream md(path() / "r/summary.md");
  std::string head;
  std::getline(md, head);
  EXPECT_NE(head.find("campaign database"), std::string::npos) << head;
}

TEST_F(CampaignCli, WhereFiltersTheDropsWithTheGrammarOfResults) {
  const Cmd r = run("measurements import '" + db() + "' --db '" + (path() / "low.db").string() +
                    "' --where 'gravity_m_s2<5' --format csv");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("4 trials stored"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(",9.81,"), std::string::npos) << r.out;
  const Cmd bad = run("model table3 '" + db() + "' --where 'gravity<5'");
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_NE(bad.out.find("found column 'gravity'"), std::string::npos) << bad.out;
  // The imported file is an input too, filtered on the trial fields.
  const Cmd again = run("model table3 '" + (path() / "low.db").string() + "'");
  EXPECT_EQ(again.code, 2) << again.out;  // 4 trials: fewer than the 6 a model needs
  EXPECT_NE(again.out.find("imported SQLite file, 4 trials"), std::string::npos) << again.out;
}

TEST_F(CampaignCli, FromRunsFindsTheCampaignTraces) {
  const std::string out = (path() / "fr").string();
  const Cmd r = run("measurements from-runs '" + (path() / "c.files").string() + "' --out '" + out + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("8 DEM trials written"), std::string::npos) << r.out;
  const Cmd t3 = run("model table3 '" + out + "'");
  EXPECT_EQ(t3.code, 0) << t3.out;
  EXPECT_NE(t3.out.find("lab campaign folder, 8 trials"), std::string::npos) << t3.out;
}

TEST_F(CampaignCli, GroupByGivesTheMeansStdAndCountsComputedByHand) {
  const Cmd all = run("results --db '" + db() + "' --format json", false);
  ASSERT_EQ(all.code, 0) << all.out;
  std::map<std::pair<double, double>, std::vector<double>> apeak;
  for (const auto& r : json::parse(all.out))
    if (r["apeak_m_s2"].is_number())
      apeak[{r["gravity_m_s2"].get<double>(), r["impact_speed_m_s"].get<double>()}].push_back(
          r["apeak_m_s2"].get<double>());
  ASSERT_EQ(apeak.size(), 4u);
  const Cmd g = run("results --db '" + db() + "' --group-by gravity_m_s2,impact_speed_m_s --format json", false);
  ASSERT_EQ(g.code, 0) << g.out;
  const json groups = json::parse(g.out);
  ASSERT_EQ(groups.size(), 4u) << g.out;
  for (const auto& grp : groups) {
    const auto& v = apeak.at({grp["gravity_m_s2"].get<double>(), grp["impact_speed_m_s"].get<double>()});
    double mean = 0, ss = 0;
    for (double x : v) mean += x / static_cast<double>(v.size());
    for (double x : v) ss += (x - mean) * (x - mean);
    const auto& m = grp["metrics"]["apeak_m_s2"];
    EXPECT_EQ(m["count"].get<std::size_t>(), v.size());
    EXPECT_NEAR(m["mean"].get<double>(), mean, 1e-9 * std::abs(mean));
    EXPECT_NEAR(m["std"].get<double>(), std::sqrt(ss / static_cast<double>(v.size() - 1)), 1e-9 * std::abs(mean));
    EXPECT_EQ(grp["rows"].get<int>(), 2);
  }
  const Cmd csv = run("results --db '" + db() + "' --group-by gravity_m_s2 --format csv", false);
  EXPECT_EQ(csv.out.rfind("gravity_m_s2,rows,", 0), 0u) << csv.out;
  const Cmd table = run("results --db '" + db() + "' --group-by gravity_m_s2", false);
  EXPECT_NE(table.out.find("apeak_m_s2_mean"), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("(2 groups)"), std::string::npos) << table.out;
}

TEST_F(CampaignCli, ADropThatCannotBeMeasuredIsListedWithTheReason) {
  // A copy of the campaign in which one drop's trace never makes contact.
  const fs::path copy = path() / "copy";
  fs::create_directories(copy);
  ASSERT_EQ(run("results --db '" + db() + "' --limit 0").code, 0);
  fs::copy_file(db(), copy / "c.db");
  fs::copy(path() / "c.files", copy / "c.files", fs::copy_options::recursive);
  fs::path victim;
  for (const auto& e : fs::directory_iterator(copy / "c.files/traces")) victim = e.path();
  ASSERT_FALSE(victim.empty());
  auto td = gravsweep::results::read_trace(victim);
  for (auto& a : td.raw.accel_up_m_s2) a = -td.info.gravity_m_s2;  // free fall only
  fs::remove(victim);
  gravsweep::results::write_trace(victim, td);
  const Cmd r = run("measurements import '" + (copy / "c.db").string() + "' --db '" + (copy / "t.db").string() + "'");
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("not measurable: " + victim.string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("never makes contact"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("7 trials stored"), std::string::npos) << r.out;
}

// `gravsweep export` on a real tiny impact campaign: the finished drops become a measurement
// campaign on disk (trials.csv, decimated traces, scenarios, results.csv) that
// `gravsweep measurements import` reads back with metrics close to the campaign's own.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "db/database.h"
#include "results/io/bed_file.h"
#include "scheduler/pipeline/impact_runners.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
using nlohmann::json;

namespace {

std::vector<std::string> lines_of(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::vector<std::string> out;
  for (std::string l; std::getline(f, l);) {
    if (!l.empty() && l.back() == '\r') l.pop_back();
    out.push_back(l);
  }
  return out;
}

/// Gives every bed file of the campaign's files root this code version (as a build of another
/// commit would have written it); returns how many.
int stamp_beds(const std::filesystem::path& files_root, const std::string& version) {
  int n = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(files_root)) {
    if (e.path().extension() != ".h5" || e.path().parent_path().filename() == "traces") continue;
    try {
      Particles grains;
      results::BedFacts bed = results::read_bed(e.path(), grains);
      bed.code_version = version;
      results::write_bed(e.path(), grains, bed);
      ++n;
    } catch (const std::exception&) {  // not a bed file
    }
  }
  return n;
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace

TEST(CliExport, FinishedDropsBecomeAMeasurementCampaign) {
  TempDir d;
  write_text(d.path / "spec.json", tiny_speed_sweep("exp", {0.4, 0.6}));
  ASSERT_EQ(run_cli({"submit", "spec.json", "--db", "c.db"}, d.path).code, 0);
  auto r = run_cli({"work", "--db", "c.db", "--workers", "2", "--threads", "1", "--quiet"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  {  // the drops and their bed as a clean commit's build made them (this test's own build may be dirty)
    db::Database db((d.path / "c.db").string());
    db.exec("UPDATE results SET code_version='0.1.0+0123456789ab'");
  }
  ASSERT_EQ(stamp_beds(d.path / "c.files", "0.1.0+0123456789ab"), 1);
  r = run_cli({"export", "--db", "c.db", "--out", "ds", "--rate-hz", "2000"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(json::parse(read_text(d.path / "ds" / "provenance.json"))["drops_by_code_version"],
            (json{{"0.1.0+0123456789ab", 2}}));
  EXPECT_EQ(json::parse(read_text(d.path / "ds" / "provenance.json"))["beds_by_code_version"],
            (json{{"0.1.0+0123456789ab", 1}}));
  EXPECT_NE(r.out.find("2 drops exported"), std::string::npos) << r.out;
  const auto trials = lines_of(d.path / "ds" / "trials.csv");
  ASSERT_EQ(trials.size(), 3u);
  EXPECT_EQ(trials[0].rfind("trial_id,trace_file,gravity_m_s2,impact_speed_m_s,fill_height_m,", 0), 0u) << trials[0];
  EXPECT_NE(trials[1].find(",dem,"), std::string::npos) << trials[1];
  // One trace per trial at 2 kHz (every 5th sample of the 10 kHz record), with its scenario.
  const std::string job = trials[1].substr(0, trials[1].find(','));
  const auto trace = lines_of(d.path / "ds" / "traces" / (job + ".csv"));
  ASSERT_GT(trace.size(), 20u);
  EXPECT_EQ(trace[0], "t_s,accel_m_s2,position_m,velocity_m_s");
  std::istringstream s1(trace[1]), s2(trace[2]);
  double t1 = 0, t2 = 0;
  s1 >> t1;
  s2 >> t2;
  EXPECT_NEAR(t2 - t1, 5e-4, 1e-6);
  EXPECT_TRUE(std::filesystem::exists(d.path / "ds" / "scenarios" / (job + ".json")));
  EXPECT_EQ(lines_of(d.path / "ds" / "results.csv").size(), 3u);
  // The folder is a measurement campaign that the import reads.
  r = run_cli({"measurements", "import", "ds", "--db", "ds.db"}, d.path);
  EXPECT_EQ(r.code, 0) << r.err << r.out;
  // Clean drops on a bed from a build with uncommitted changes: refused as a dirty drop is,
  // naming the bed, and nothing is written.
  ASSERT_EQ(stamp_beds(d.path / "c.files", "0.1.0+0123456789ab-dirty"), 1);
  r = run_cli({"export", "--db", "c.db", "--out", "dirty_bed"}, d.path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("1 of 1 beds come from builds with uncommitted changes"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(d.path / "dirty_bed"));
  // A drop from a build with uncommitted changes: refused, naming it, and nothing is written;
  // exported with --allow-dirty, which provenance.json records.
  {
    db::Database db((d.path / "c.db").string());
    db.exec(
        "UPDATE results SET code_version='0.1.0+0123456789ab-dirty' WHERE rowid=(SELECT MIN(rowid) FROM results "
        "WHERE kind='drop')");
  }
  r = run_cli({"export", "--db", "c.db", "--out", "dirty"}, d.path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("1 of 2 drops come from builds with uncommitted changes: 0.1.0+0123456789ab-dirty (1 drops)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(d.path / "dirty"));
  r = run_cli({"export", "--db", "c.db", "--out", "dirty", "--allow-dirty"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(json::parse(read_text(d.path / "dirty" / "provenance.json"))["allow_dirty"], true);
  // Bad input: exit 2, naming what is wrong.
  r = run_cli({"export", "--db", "nope.db", "--out", "x"}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("nope.db"), std::string::npos) << r.err;
  r = run_cli({"export", "--db", "c.db", "--out", "x", "--rate-hz", "0"}, d.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--rate-hz"), std::string::npos) << r.err;
}

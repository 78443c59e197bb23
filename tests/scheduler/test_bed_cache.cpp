// `gravsweep work --bed-cache DIR`: prepared beds shared between campaigns and machines
// (scheduler/pipeline/bed_cache.h). A campaign stores each bed it prepares under its bed job id;
// another campaign with the same bed copies it instead of preparing it, and its drops give the
// same metrics bit for bit; a cached bed that changed is refused naming the file, never used.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "scheduler/pipeline/impact_runners.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

/// One bed, one drop of the tiny scenario.
std::string one_drop_spec() {
  json spec;
  spec["sweep"] = "cache";
  spec["base"] = json::parse(tiny_base());
  spec["axes"] =
      json::array({{{"name", "impact_speed_m_s"}, {"pointer", "/projectile/impact_speed_m_s"}, {"values", {0.5}}}});
  return spec.dump(2);
}

struct Campaign {
  CmdResult work;
  std::string bed_id, bed_report, drop_zstop, bed_error;
  std::int64_t drops_done = 0;
};

/// Submits the one-drop spec into `<dir>/<name>.db` and runs one worker with --bed-cache `cache`.
Campaign run_campaign(const fs::path& dir, const std::string& name, const fs::path& cache) {
  write_text(dir / "spec.json", one_drop_spec());
  const std::string db_file = name + ".db";
  EXPECT_EQ(run_cli({"submit", "spec.json", "--db", db_file}, dir).code, 0);
  Campaign c;
  c.work = run_cli(
      {"work", "--db", db_file, "--threads", "1", "--quiet", "--backoff", "0", "--bed-cache", cache.string()}, dir);
  db::Database db((dir / db_file).string());
  c.bed_id = sql_text(db, "SELECT job_id FROM jobs WHERE kind='bed'");
  c.bed_report = sql_text(db, "SELECT coalesce(report_json,'') FROM attempts WHERE kind='bed' AND outcome='done'");
  c.bed_error = sql_text(db, "SELECT coalesce(last_error,'') FROM jobs WHERE kind='bed'");
  c.drops_done = sql_int(db, "SELECT count(*) FROM jobs WHERE kind='drop' AND state='done'");
  // results columns appear with the first finished drop
  if (c.drops_done > 0) c.drop_zstop = sql_text(db, "SELECT CAST(zstop_m AS TEXT) FROM results WHERE kind='drop'");
  return c;
}

}  // namespace

TEST(BedCache, ASecondCampaignTakesTheStoredBedAndGetsTheSameDrop) {
  TempDir d;
  const fs::path cache = d.path / "beds";
  const Campaign first = run_campaign(d.path, "first", cache);
  ASSERT_EQ(first.work.code, 0) << first.work.err;
  ASSERT_FALSE(first.bed_id.empty());
  const fs::path stored = cache / (first.bed_id + ".h5");
  EXPECT_TRUE(fs::exists(stored)) << "the prepared bed is stored under its bed job id";
  EXPECT_TRUE(fs::exists(stored.string() + ".sha256")) << "with its checksum file";
  EXPECT_EQ(first.bed_report.find("from_cache"), std::string::npos) << first.bed_report;

  const Campaign second = run_campaign(d.path, "second", cache);
  ASSERT_EQ(second.work.code, 0) << second.work.err;
  EXPECT_EQ(second.bed_id, first.bed_id);
  EXPECT_NE(second.bed_report.find("\"from_cache\""), std::string::npos)
      << "the second campaign copies the bed: " << second.bed_report;
  EXPECT_NE(second.bed_report.find("grains_kept"), std::string::npos) << "and keeps its preparation report";
  ASSERT_FALSE(first.drop_zstop.empty());
  EXPECT_EQ(second.drop_zstop, first.drop_zstop) << "the same bed gives the same drop, bit for bit";
}

TEST(BedCache, AChangedCachedBedIsRefusedNamingTheFile) {
  TempDir d;
  const fs::path cache = d.path / "beds";
  const Campaign first = run_campaign(d.path, "first", cache);
  ASSERT_EQ(first.work.code, 0) << first.work.err;
  const fs::path stored = cache / (first.bed_id + ".h5");
  {  // one flipped bit near the end of the file (grain state)
    std::fstream f(stored, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(-100, std::ios::end);
    char b = 0;
    f.read(&b, 1);
    b ^= 0x10;
    f.seekp(-100, std::ios::end);
    f.write(&b, 1);
  }
  const Campaign second = run_campaign(d.path, "second", cache);
  EXPECT_EQ(second.work.code, 4) << "a dead bed job: exit code 4\n" << second.work.err;
  EXPECT_NE(second.bed_error.find(stored.string()), std::string::npos) << second.bed_error;
  EXPECT_NE(second.bed_error.find("does not match its checksum"), std::string::npos) << second.bed_error;
  EXPECT_EQ(second.drops_done, 0) << "no drop ran on a changed bed";

  fs::remove(stored.string() + ".sha256");  // a cached bed without its checksum is not trusted either
  const Campaign third = run_campaign(d.path, "third", cache);
  EXPECT_EQ(third.work.code, 4) << third.work.err;
  EXPECT_NE(third.bed_error.find("has no checksum file"), std::string::npos) << third.bed_error;
}

// `measurements import` stores a trace once, by content. Trials that point at
// one trace file share its rows (5 trials of one 93 MB trace made a 1.87 GB database); samples no
// trial names are removed on re-import; a database of the per-trial layout before is read as it is
// and moved to the shared layout when a campaign is stored into it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "db/database.h"
#include "results/measurements/campaign.h"
#include "results/model/model_spec.h"
#include "results/model/synth.h"
#include "results_helpers.h"

using namespace gravsweep;
using namespace gravsweep::results;
using gravsweep::testing::TempDir;

namespace {

/// A lab campaign in `dir` whose `n` trials all point at one trace (traces/S001.csv), with the
/// impact speeds `speeds` (one per trial; all the synthetic speed when empty).
void write_shared_trace_campaign(const std::filesystem::path& dir, int n, const std::vector<double>& speeds = {}) {
  SynthOptions o;
  o.gravity_m_s2 = {9.81};
  o.impact_speed_m_s = {0.8};
  o.repeats = 1;
  o.rest_tail_s = 2.0;  // a long record: the samples dominate the file
  write_synthetic_campaign(dir.string(), parse_model("base"), o);
  std::ifstream in(dir / "trials.csv");
  std::string header, row;
  std::getline(in, header);
  std::getline(in, row);
  in.close();
  std::ofstream out(dir / "trials.csv");
  out << header << "\n";
  for (int i = 0; i < n; ++i) {
    std::string r = row;
    r.replace(0, r.find(','), "T" + std::to_string(i + 1));
    if (!speeds.empty()) {
      // impact_speed_m_s is the fourth column of the synthetic trials.csv
      std::vector<std::string> f;
      std::stringstream ss(r);
      for (std::string c; std::getline(ss, c, ',');) f.push_back(c);
      f[3] = std::to_string(speeds[static_cast<std::size_t>(i)]);
      r.clear();
      for (std::size_t k = 0; k < f.size(); ++k) r += (k ? "," : "") + f[k];
    }
    out << r << "\n";
  }
}

std::int64_t count(db::Database& db, const std::string& sql) {
  db::Statement q(db, sql);
  EXPECT_TRUE(q.step()) << sql;
  return q.get_int(0);
}

std::uintmax_t import_into(const std::filesystem::path& campaign, const std::filesystem::path& dbfile) {
  const Campaign c = load_campaign(campaign.string());
  EXPECT_TRUE(c.issues.empty()) << c.issues.front().to_string();
  {
    db::Database db(dbfile.string());
    store_campaign(db, c);
    db.exec("VACUUM");
  }
  return std::filesystem::file_size(dbfile);
}

void expect_same_samples(const Campaign& a, const Campaign& b) {
  ASSERT_EQ(a.trials.size(), b.trials.size());
  for (std::size_t i = 0; i < a.trials.size(); ++i) {
    EXPECT_EQ(a.trials[i].info.trial_id, b.trials[i].info.trial_id);
    EXPECT_EQ(a.trials[i].raw.accel_up_m_s2, b.trials[i].raw.accel_up_m_s2);
    EXPECT_EQ(a.trials[i].processed.accel_up_m_s2, b.trials[i].processed.accel_up_m_s2);
    EXPECT_EQ(a.trials[i].processed.depth_m, b.trials[i].processed.depth_m);
    EXPECT_EQ(a.trials[i].fit_end, b.trials[i].fit_end);
  }
}

}  // namespace

TEST(TraceStore, FiveTrialsOfOneTraceStoreItOnce) {
  TempDir d;
  write_shared_trace_campaign(d.path / "one", 1);
  write_shared_trace_campaign(d.path / "five", 5);
  const auto one = import_into(d.path / "one", d.path / "one.db");
  const auto five = import_into(d.path / "five", d.path / "five.db");
  // Five trials of one trace: the trace's rows once, not five times (the trial rows are small).
  EXPECT_LT(static_cast<double>(five), 1.2 * static_cast<double>(one)) << one << " vs " << five << " bytes";
  db::Database db((d.path / "five.db").string(), 30000, true);
  const Campaign c = load_campaign_db(db);
  ASSERT_EQ(c.trials.size(), 5u);
  const auto n = static_cast<std::int64_t>(c.trials[0].processed.t_s.size());
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM traces"), 1);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM trace_samples"), n);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM processed_samples"), n);
  EXPECT_EQ(count(db, "SELECT COUNT(DISTINCT trace_id) FROM trials"), 1);
  // Every trial still has its rows, through the view.
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM trial_samples"), 5 * n);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM trial_samples WHERE trial_id = 'T4'"), n);
  for (const auto& t : c.trials) EXPECT_EQ(t.raw.accel_up_m_s2, c.trials[0].raw.accel_up_m_s2);
}

TEST(TraceStore, TrialsProcessedDifferentlyShareTheRawRecordOnly) {
  TempDir d;
  write_shared_trace_campaign(d.path / "c", 3, {0.78, 0.8, 0.82});
  import_into(d.path / "c", d.path / "c.db");
  db::Database db((d.path / "c.db").string(), 30000, true);
  // One raw record; three processed ones (velocity and depth integrate each trial's own speed).
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM traces"), 1);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM processed_traces"), 3);
  const Campaign back = load_campaign_db(db);
  const Campaign c = load_campaign((d.path / "c").string());
  expect_same_samples(back, c);
  EXPECT_NE(back.trials[0].processed.depth_m, back.trials[2].processed.depth_m);
}

TEST(TraceStore, ReimportRemovesSamplesNoTrialNames) {
  TempDir d;
  SynthOptions o;
  o.gravity_m_s2 = {9.81};
  o.impact_speed_m_s = {0.4, 0.8};
  o.repeats = 1;
  write_synthetic_campaign((d.path / "a").string(), parse_model("base"), o);
  o.seed = 2;  // the same trial ids, other records
  write_synthetic_campaign((d.path / "b").string(), parse_model("base"), o);
  import_into(d.path / "a", d.path / "c.db");
  import_into(d.path / "b", d.path / "c.db");
  db::Database db((d.path / "c.db").string(), 30000, true);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM trials"), 2);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM traces"), 2);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM processed_traces"), 2);
  EXPECT_EQ(count(db, "SELECT COUNT(*) FROM trace_samples"), count(db, "SELECT SUM(samples) FROM traces"));
  expect_same_samples(load_campaign_db(db), load_campaign((d.path / "b").string()));
}

TEST(TraceStore, ADatabaseOfThePerTrialLayoutIsReadAndMovedToTheSharedOne) {
  TempDir d;
  write_shared_trace_campaign(d.path / "c", 3);
  import_into(d.path / "c", d.path / "old.db");
  const Campaign want = load_campaign((d.path / "c").string());
  {
    // The layout of gravsweep before: a table trial_samples with every trial's own rows.
    db::Database db((d.path / "old.db").string());
    db.exec(
        "CREATE TABLE old_samples (trial_id TEXT NOT NULL REFERENCES trials(trial_id) ON DELETE CASCADE, "
        "sample INTEGER NOT NULL, t_s REAL, accel_raw_m_s2 REAL, accel_filtered_m_s2 REAL, velocity_m_s REAL, "
        "depth_m REAL, PRIMARY KEY (trial_id, sample));"
        "INSERT INTO old_samples SELECT * FROM trial_samples; DROP VIEW trial_samples;"
        "ALTER TABLE old_samples RENAME TO trial_samples;"
        "DROP TABLE traces; DROP TABLE trace_samples; DROP TABLE processed_traces; DROP TABLE processed_samples;"
        "UPDATE trials SET trace_id = NULL, processed_id = NULL;");
  }
  {
    db::Database db((d.path / "old.db").string(), 30000, true);  // read as it is, read-only
    expect_same_samples(load_campaign_db(db), want);
  }
  {
    db::Database db((d.path / "old.db").string());
    store_campaign(db, Campaign{});  // storing into it moves it to the shared layout
    EXPECT_EQ(count(db, "SELECT COUNT(*) FROM sqlite_master WHERE type = 'view' AND name = 'trial_samples'"), 1);
    EXPECT_EQ(count(db, "SELECT COUNT(*) FROM traces"), 1);
    EXPECT_EQ(count(db, "SELECT COUNT(*) FROM trials WHERE trace_id IS NULL"), 0);
  }
  db::Database db((d.path / "old.db").string(), 30000, true);
  expect_same_samples(load_campaign_db(db), want);
}

// A saturated accelerometer (a flat top at its range on the fast impacts) is
// found at import, flagged in the trial record, its apeak left out of the apeak fits (Eq. 2) and
// errors, its flat top out of the trace fits, tstop kept, zstop kept while the clip moves it by
// at most kClipDepthTolerance; the flag survives SQLite, the import table and the report say so.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "db/database.h"
#include "results/measurements/campaign.h"
#include "results/model/collapse.h"
#include "results/model/model_spec.h"
#include "results/model/table3.h"
#include "results/model/synth.h"
#include "results_helpers.h"

using namespace gravsweep;
using namespace gravsweep::results;
using gravsweep::testing::TempDir;

namespace {

SynthOptions lab() {
  SynthOptions o;
  o.gravity_m_s2 = {9.81};
  o.impact_speed_m_s = {0.3, 0.5, 0.7, 0.9, 1.1, 1.3};
  o.repeats = 2;
  o.seed = 11;
  return o;
}

/// A sensor range between the slow and the fast impacts' peaks of the unclipped campaign `c`:
/// the raw peak of the fourth slowest of its six speeds.
double range_clipping_the_fast_ones(const Campaign& c) {
  std::vector<double> peaks;
  for (const auto& t : c.trials)
    peaks.push_back(*std::max_element(t.raw.accel_up_m_s2.begin(), t.raw.accel_up_m_s2.end()));
  std::sort(peaks.begin(), peaks.end());
  return peaks[peaks.size() / 2];
}

std::string read_all(const std::filesystem::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST(Clipping, AFlatTopAtTheLargestValueIsFoundANoisyPeakIsNot) {
  std::vector<double> a = {-9.8, -9.8, -9.8, 5, 40, 80, 80, 80, 80, 60, 20, 0.1, 0.0};
  const auto run = clipped_run(a);
  ASSERT_TRUE(run.has_value());
  EXPECT_EQ(run->level_m_s2, 80);
  EXPECT_EQ(run->begin, 5u);
  EXPECT_EQ(run->end, 9u);
  // Two equal samples at the top are a coincidence, not a flat top; free fall's repeated -g is
  // the record's smallest value, not its largest.
  EXPECT_FALSE(clipped_run({-9.8, -9.8, -9.8, -9.8, 5, 80, 80, 60, 0.0}).has_value());
  EXPECT_FALSE(clipped_run({-9.8, -9.8, -9.8, 5, 79.9, 80, 79.95, 60, 0.0}).has_value());
}

TEST(Clipping, ImportFlagsTheClippedTrialsAndEq2LeavesTheirApeakOut) {
  TempDir d;
  const SynthOptions free_range = lab();
  write_synthetic_campaign((d.path / "full").string(), parse_model("base"), free_range);
  const Campaign full = load_campaign((d.path / "full").string());
  ASSERT_TRUE(full.issues.empty()) << full.issues.front().to_string();
  for (const auto& t : full.trials) EXPECT_EQ(t.info.clipped_at_m_s2, 0.0) << t.info.trial_id;

  SynthOptions o = free_range;
  o.sensor_range_m_s2 = range_clipping_the_fast_ones(full);
  write_synthetic_campaign((d.path / "clip").string(), parse_model("base"), o);
  const Campaign clip = load_campaign((d.path / "clip").string());
  ASSERT_TRUE(clip.issues.empty()) << clip.issues.front().to_string();
  ASSERT_EQ(clip.trials.size(), full.trials.size());

  int clipped = 0;
  for (std::size_t i = 0; i < clip.trials.size(); ++i) {
    const auto& t = clip.trials[i];
    if (t.info.clipped_at_m_s2 > 0) {
      ++clipped;
      EXPECT_DOUBLE_EQ(t.info.clipped_at_m_s2, o.sensor_range_m_s2) << t.info.trial_id;
      EXPECT_GE(t.info.clipped_samples, 3.0);
      EXPECT_FALSE(clip_exclusion(t, ClippedMetric::apeak).empty());
      EXPECT_TRUE(clip_exclusion(t, ClippedMetric::tstop).empty());
      EXPECT_LT(t.processed.metrics.apeak_m_s2, full.trials[i].processed.metrics.apeak_m_s2) << t.info.trial_id;
      // The trace fits start after the flat top.
      const auto run = clipped_run(t.raw.accel_up_m_s2);
      ASSERT_TRUE(run.has_value());
      EXPECT_GE(t.fit_begin, run->end);
      // tstop: threshold crossings far below the clip, as without it.
      EXPECT_NEAR(t.processed.metrics.tstop_s, full.trials[i].processed.metrics.tstop_s, 2.0 / o.sample_rate_hz);
      // zstop, when kept, within the stated tolerance of the unclipped record's.
      if (clip_exclusion(t, ClippedMetric::zstop).empty()) {
        EXPECT_NEAR(t.processed.metrics.zstop_m, full.trials[i].processed.metrics.zstop_m,
                    kClipDepthTolerance * full.trials[i].processed.metrics.zstop_m + 1e-4)
            << t.info.trial_id;
      }
      EXPECT_NE(clip_summary(t).find("lower bound"), std::string::npos) << clip_summary(t);
    } else {
      EXPECT_TRUE(clip_summary(t).empty());
    }
  }
  EXPECT_GE(clipped, 4);
  EXPECT_LE(clipped, 8);

  // Eq. 2 sees the trials that did not clip, exactly as if the clipped ones were not there.
  Campaign kept = clip;
  kept.trials.clear();
  for (const auto& t : clip.trials)
    if (!(t.info.clipped_at_m_s2 > 0)) kept.trials.push_back(t);
  const auto rows = table3(clip);
  const auto want = table3(kept);
  ASSERT_EQ(rows.size(), 1u);
  ASSERT_EQ(want.size(), 1u);
  EXPECT_EQ(rows[0].trials, want[0].trials);
  EXPECT_DOUBLE_EQ(rows[0].f0_N, want[0].f0_N);
  EXPECT_DOUBLE_EQ(rows[0].inv_d1_1_m, want[0].inv_d1_1_m);
  EXPECT_NE(rows[0].note.find("clipped"), std::string::npos) << rows[0].note;
  // Taken as real (as before: nothing flagged them), the flat tops enter Eq. 2 and move it.
  Campaign as_real = clip;
  for (auto& t : as_real.trials) t.info.clipped_at_m_s2 = 0;
  const auto before = table3(as_real);
  EXPECT_EQ(before[0].trials, rows[0].trials + clipped);
  EXPECT_NE(before[0].inv_d1_1_m, rows[0].inv_d1_1_m);

  // The collapse leaves the clipped apeaks out too.
  std::size_t finite_apeaks = 0;
  for (const auto& s : scaled_trials(clip)) finite_apeaks += std::isfinite(s.apeak_over_g);
  EXPECT_EQ(finite_apeaks, clip.trials.size() - static_cast<std::size_t>(clipped));
}

TEST(Clipping, TheFlagIsStoredAndReadBackFromSqlite) {
  TempDir d;
  SynthOptions o = lab();
  o.sensor_range_m_s2 = 25;
  write_synthetic_campaign((d.path / "c").string(), parse_model("base"), o);
  const Campaign c = load_campaign((d.path / "c").string());
  ASSERT_TRUE(c.issues.empty()) << c.issues.front().to_string();
  {
    db::Database db((d.path / "lab.db").string());
    store_campaign(db, c);
  }
  const Campaign back = load_campaign_any((d.path / "lab.db").string());
  ASSERT_EQ(back.trials.size(), c.trials.size());
  int clipped = 0;
  for (std::size_t i = 0; i < c.trials.size(); ++i) {
    EXPECT_EQ(back.trials[i].info.clipped_at_m_s2, c.trials[i].info.clipped_at_m_s2);
    EXPECT_EQ(back.trials[i].info.clipped_samples, c.trials[i].info.clipped_samples);
    EXPECT_EQ(back.trials[i].fit_begin, c.trials[i].fit_begin);
    clipped += c.trials[i].info.clipped_at_m_s2 > 0;
  }
  EXPECT_GT(clipped, 0);
}

TEST(Clipping, ImportTableAndReportNameTheClippedTrials) {
  TempDir d;
  const auto s =
      gravsweep::testing::run_gravsweep("synth --out '" + d.str() +
                                            "/c' --model base --gravity 9.81 --speeds 0.3,0.7,1.1,1.3 --repeats 2 "
                                            "--sensor-range 30",
                                        true);
  ASSERT_EQ(s.code, 0) << s.out;
  const auto r = gravsweep::testing::run_gravsweep(
      "measurements import '" + d.str() + "/c' --db '" + d.str() + "/lab.db' --format csv", true);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("clipped_at_m_s2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(",30\r\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("accelerometer clipped at 30 m/s2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("apeak"), std::string::npos) << r.out;
  const auto rep = gravsweep::testing::run_gravsweep(
      "report '" + d.str() + "/lab.db' --out '" + d.str() + "/report' --folds 2", true);
  if (rep.code != 0 && rep.out.find("matplotlib") != std::string::npos) GTEST_SKIP() << "no matplotlib: " << rep.out;
  ASSERT_EQ(rep.code, 0) << rep.out;
  const std::string md = read_all(d.path / "report" / "summary.md");
  EXPECT_NE(md.find("Clipped accelerometer records"), std::string::npos) << md;
  EXPECT_NE(md.find("lower bound"), std::string::npos) << md;
}

// The Froude-number collapse (results/model/collapse.h) on synthetic campaigns across four gravity
// levels with a known truth: Poncelet resistance with f0 = 1.6 m g and a fixed 1/d1 is Froude-
// scaled (R = m g F(z/D, v^2/(g D))) and must collapse; a constant 0.5 N cohesion, which does not
// scale with g, dominates at low gravity and must not.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "results/measurements/campaign.h"
#include "results/model/collapse.h"
#include "results/model/model.h"
#include "results/model/synth.h"
#include "results_helpers.h"

namespace gravsweep::results {
namespace {

using gravsweep::testing::TempDir;

Campaign four_levels(const std::string& model, const TempDir& d) {
  SynthOptions o;
  o.gravity_m_s2 = {9.81, 1.62, 0.1, 0.01};
  o.repeats = 2;
  o.seed = 3;
  const std::string dir = (d.path / "c").string();
  write_synthetic_campaign(dir, parse_model(model), o);
  return load_campaign(dir);
}

TEST(Collapse, AFroudeScaledTruthFallsOnOneCurve) {
  TempDir d;
  const auto rows = collapse(four_levels("base", d));
  ASSERT_EQ(rows.size(), 3u);
  for (const auto& r : rows) {
    EXPECT_EQ(r.levels, 4) << r.metric;
    EXPECT_EQ(r.trials, 64) << r.metric;
    // Depth and duration: as close to one curve as each level is to its own (the repeat scatter).
    if (r.metric != "apeak_over_g") EXPECT_LT(r.collapse_ratio, 1.2) << r.metric;
    EXPECT_LT(r.collapse_ratio, 1.6) << r.metric;
  }
}

TEST(Collapse, AResistanceThatDoesNotScaleWithGravityBreaksIt) {
  TempDir d;
  const auto rows = collapse(four_levels("base+cohesion", d));
  for (const auto& r : rows) {
    if (r.metric == "apeak_over_g") continue;
    EXPECT_GT(r.collapse_ratio, 2.5) << r.metric;
    EXPECT_GT(r.between_levels_pct, 50) << r.metric;  // the levels lie apart at equal Fr
  }
}

// A level with only two speeds (repeats at slightly different measured impact speeds) gets a
// straight line, not a parabola bent between two repeats: its distance to the other levels
// stays that of a Froude-scaled truth.
TEST(Collapse, ALevelWithTwoSpeedsIsFittedByALine) {
  TempDir d;
  Campaign c = four_levels("base", d);
  std::erase_if(c.trials, [](const MeasuredTrial& t) {
    return same_gravity_level(t.info.gravity_m_s2, 0.01) && t.info.impact_speed_m_s > 0.3;
  });
  const auto rows = collapse(c);
  for (const auto& r : rows) {
    EXPECT_EQ(r.trials, 52) << r.metric;  // 16 per level, 4 at 0.01 m/s2
    if (r.metric == "apeak_over_g") continue;
    EXPECT_LT(r.between_levels_pct, 20) << r.metric;
    EXPECT_LT(r.collapse_ratio, 1.3) << r.metric;
  }
}

TEST(Collapse, ScaledMetricsUseTheProjectileDiameterAndGravity) {
  TempDir d;
  const Campaign c = four_levels("base", d);
  const auto st = scaled_trials(c);
  ASSERT_EQ(st.size(), c.trials.size());
  const auto& t = c.trials.front();
  const double g = t.info.gravity_m_s2, D = t.info.projectile_diameter_m;
  EXPECT_DOUBLE_EQ(st.front().froude, t.processed.metrics.vc_m_s / std::sqrt(g * D));
  EXPECT_DOUBLE_EQ(st.front().zstop_over_D, t.processed.metrics.zstop_m / D);
  EXPECT_DOUBLE_EQ(st.front().tstop_sqrt_g_over_D, t.processed.metrics.tstop_s * std::sqrt(g / D));
  EXPECT_DOUBLE_EQ(st.front().apeak_over_g, t.processed.metrics.apeak_m_s2 / g);
}

}  // namespace
}  // namespace gravsweep::results

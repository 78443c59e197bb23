// The Froude-number collapse (results/model/collapse.h) on synthetic campaigns across four gravity
// levels with a known truth: Poncelet resistance with f0 = 1.6 m g and a fixed 1/d1 is Froude-
// scaled (R = m g F(z/D, v^2/(g D))) and must collapse; a constant 0.5 N cohesion, which does not
// scale with g, dominates at low gravity and must not.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "results/measurements/campaign.h"
#include "results/model/collapse.h"
#include "results/model/model_spec.h"
#include "results/model/stats.h"
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

/// A gravity sweep of a Froude-scaled truth over four decades of g: speeds by Froude number, the
/// drop's own times (free fall, force fluctuation, rest) in units of sqrt(D / g) and the grain
/// contacts' chatter white in those units up to the sample rate (SynthOptions::contact_chatter_g),
/// one accelerometer at 1400 Hz for all levels.
Campaign froude_sweep(const TempDir& d, unsigned seed) {
  SynthOptions o;
  o.gravity_m_s2 = {9.81, 0.1, 0.01, 0.001};
  o.froude = {0.3, 1.0, 3.0};
  o.froude_times = true;
  o.contact_chatter_g = 0.03;
  o.repeats = 3;
  o.seed = seed;
  const std::string dir = (d.path / fmt::format("froude{}", seed)).string();
  write_synthetic_campaign(dir, parse_model("base"), o);
  return load_campaign(dir, kPaperCutoff_hz, {"froude", ""});  // records sized in the drop's own time
}

// Processed in each drop's own scales (the default time scale), a Froude-scaled truth shows no
// level effect at equal Fr in any of the three metrics (nested ANOVA, p >= 0.01) and its levels lie
// within the repeat scatter; processed in the paper's hertz and seconds at every level, the filter
// and the hold are 31-99 times wider in units of sqrt(g / D) below 1 g and the duration and the
// peak read the sensor instead: their level effect is significant.
TEST(Collapse, AFroudeScaledTruthOverFourDecadesCollapsesInItsOwnScalesOnly) {
  TempDir d;
  Campaign c = froude_sweep(d, 5);
  ASSERT_EQ(c.trials.size(), 36u);
  const auto own = collapse(c);
  reprocess_campaign(c, {"fixed", ""});
  const auto fixed = collapse(c);
  int broken = 0;
  for (std::size_t k = 0; k < own.size(); ++k) {
    const auto& r = own[k];
    SCOPED_TRACE(r.metric);
    std::printf("%s: own scales level %.3g %% repeats %.3g %% p %.3g; fixed level %.3g %% repeats %.3g %% p %.3g\n",
                r.metric.c_str(), r.level_scatter_pct, r.repeat_scatter_pct, r.level_p, fixed[k].level_scatter_pct,
                fixed[k].repeat_scatter_pct, fixed[k].level_p);
    EXPECT_EQ(r.cells, 12);
    EXPECT_EQ(r.level_df, 9);
    EXPECT_EQ(r.repeat_df, 24);
    EXPECT_GE(r.level_p, kLevelEffectP);
    // The fixed processing either separates the levels or buries them in a scatter it adds.
    broken += fixed[k].level_p < kLevelEffectP || fixed[k].repeat_scatter_pct > 2 * r.repeat_scatter_pct;
  }
  EXPECT_EQ(broken, 3) << "every metric reads the sensor under the fixed processing";
}

// The nested analysis of variance on a hand-made set: two Froude numbers at two levels, two
// repeats a cell. The levels differ by a factor e^0.5 at equal Fr, the repeats by e^(+-0.01):
// F = MS_levels / MS_repeats with 2 and 4 degrees of freedom, p tiny; with the level shift
// removed, F is 0 and nothing differs.
TEST(Collapse, TheLevelEffectIsANestedAnalysisOfVariance) {
  Campaign c;
  auto add = [&](double g, double fr, double z_over_D) {
    MeasuredTrial t;
    t.info.gravity_m_s2 = g;
    t.info.projectile_diameter_m = 0.1;
    t.processed.metrics.vc_m_s = fr * std::sqrt(g * 0.1);
    t.processed.metrics.zstop_m = z_over_D * 0.1;
    t.processed.metrics.tstop_s = 1.0;
    t.processed.metrics.apeak_m_s2 = g;
    c.trials.push_back(t);
  };
  for (double shift : {0.5, 0.0}) {
    c.trials.clear();
    for (double g : {9.81, 0.1})
      for (double fr : {0.5, 2.0})
        for (double e : {-0.01, 0.01}) add(g, fr, std::exp(std::log(fr) + e + (g < 1 ? shift : 0.0)));
    const auto rows = collapse(c);
    const auto& z = rows.front();
    ASSERT_EQ(z.metric, "zstop_over_D");
    EXPECT_EQ(z.cells, 4);
    EXPECT_EQ(z.level_df, 2);
    EXPECT_EQ(z.repeat_df, 4);
    // MS_repeats = 8 (0.01)^2 / 4; MS_levels = sum over cells of n (mean - Fr mean)^2 / 2.
    const double ms_rep = 8 * 0.01 * 0.01 / 4, ms_lev = 4 * 2 * 0.25 * 0.25 / 2;
    if (shift > 0) {
      EXPECT_NEAR(z.level_f, ms_lev / ms_rep, 1e-6 * ms_lev / ms_rep);
      // For d1 = 2, P(F > f) = (1 + 2 f / d2)^(-d2 / 2) in closed form.
      EXPECT_NEAR(z.level_p, std::pow(1 + 2 * z.level_f / 4, -2.0), 1e-12);
      EXPECT_LT(z.level_p, 1e-5);
      EXPECT_NEAR(z.level_scatter_pct, 100 * (std::exp(std::sqrt((ms_lev - ms_rep) / 2)) - 1), 1e-6);
    } else {
      EXPECT_NEAR(z.level_f, 0.0, 1e-9);
      EXPECT_NEAR(z.level_p, 1.0, 1e-9);
      EXPECT_EQ(z.level_scatter_pct, 0.0);
    }
    EXPECT_NEAR(z.repeat_scatter_pct, 100 * (std::exp(std::sqrt(ms_rep)) - 1), 1e-6);
  }
}

// The F distribution's upper tail against tabulated values (A&S Table 26.9: F(2, 10) = 4.10 at
// 5 %, F(4, 20) = 4.43 at 1 %) and I_x(1, 1) = x, I_x(a, b) + I_{1-x}(b, a) = 1.
TEST(Stats, TheFDistributionsUpperTailMatchesTheTables) {
  EXPECT_NEAR(f_upper_p(4.10, 2, 10), 0.05, 5e-4);
  EXPECT_NEAR(f_upper_p(4.43, 4, 20), 0.01, 2e-4);
  EXPECT_NEAR(f_upper_p(1.0, 10, 10), 0.5, 1e-12);
  EXPECT_NEAR(regularized_beta(1, 1, 0.3), 0.3, 1e-14);
  EXPECT_NEAR(regularized_beta(2.5, 0.7, 0.4) + regularized_beta(0.7, 2.5, 0.6), 1.0, 1e-12);
  EXPECT_EQ(f_upper_p(0.0, 2, 10), 1.0);
  EXPECT_TRUE(std::isnan(f_upper_p(1.0, 0, 10)));
}

}  // namespace
}  // namespace gravsweep::results

// One gravity-scaled law across gravity levels (results/model/level_out.h, regimes.h) on
// synthetic campaigns over four levels with a known truth: leave-one-level-out prediction, and the
// crossover from inertial drag to quasi-static friction along the drops.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "results/measurements/campaign.h"
#include "results/model/level_out.h"
#include "results/model/discover.h"
#include "results/model/fit.h"
#include "results/model/model_spec.h"
#include "results/model/predict.h"
#include "results/model/regimes.h"
#include "results/model/synth.h"
#include "results_helpers.h"

namespace gravsweep::results {
namespace {

using gravsweep::testing::TempDir;

const std::vector<double> kFourLevels_m_s2{9.81, 1.62, 0.1, 0.01};

/// 4 levels x 8 speeds (0.1-1.2 m/s) x 2 repeats = 64 trials of the synthetic lab's default noise.
SynthOptions four_levels(unsigned seed) {
  SynthOptions o;
  o.gravity_m_s2 = kFourLevels_m_s2;
  o.repeats = 2;
  o.seed = seed;
  return o;
}

Campaign synth_campaign(const std::string& truth, const SynthOptions& o, const TempDir& d) {
  const std::string dir = (d.path / "c").string();
  write_synthetic_campaign(dir, parse_model(truth), o);
  return load_campaign(dir);
}

void print_rows(const char* label, const std::vector<LevelOutRow>& rows) {
  for (const auto& r : rows)
    std::printf(
        "%s: held out g %g (%s, %d drops): zstop %.2f %%, tstop %.2f %%, apeak %.1f %%; phi %.3g, 1/d1 %.3g; %s\n",
        label, r.g_m_s2, r.inside ? "inside" : "outside", r.trials, r.zstop_median_abs_err_pct,
        r.tstop_median_abs_err_pct, r.apeak_median_abs_err_pct, r.law.coef(0), r.law.coef(1), r.verdict.c_str());
}

/// The state at first contact of a trial (its g, D, m and impact speed).
TermContext first_contact(const Trial& t) {
  TermContext c;
  c.g_m_s2 = t.gravity_m_s2;
  c.diameter_m = t.projectile_diameter_m;
  c.mass_kg = t.projectile_mass_kg;
  c.fill_height_m = t.fill_height_m;
  c.vc_m_s = c.v_m_s = t.impact_speed_m_s;
  return c;
}

const LevelOutRow& row_at(const std::vector<LevelOutRow>& rows, double g) {
  for (const auto& r : rows)
    if (same_gravity_level(r.g_m_s2, g)) return r;
  throw std::runtime_error("no held-out level " + std::to_string(g));
}

}  // namespace
}  // namespace gravsweep::results

namespace gravsweep::results {
namespace {

/// The noise of a level: the median |error| of zstop and tstop predicted by the truth itself (its
/// mean law, without the per-drop bed spread), against what the synthetic lab measured.
std::pair<double, double> truth_noise_pct(const Campaign& c, const std::string& truth, const SynthOptions& o,
                                          double g) {
  const FittedModel tm = truth_model(parse_model(truth), o.gravity_m_s2, o.mass_kg, o.diameter_m);
  std::vector<double> z, t;
  for (const auto& tr : c.trials) {
    if (!same_gravity_level(tr.info.gravity_m_s2, g)) continue;
    const Prediction p = predict(tm, tr.info);
    z.push_back(100 * (p.zstop_m - tr.processed.metrics.zstop_m) / tr.processed.metrics.zstop_m);
    t.push_back(100 * (p.tstop_s - tr.processed.metrics.tstop_s) / tr.processed.metrics.tstop_s);
  }
  return {median_abs(z), median_abs(t)};
}

/// The bound of "within the noise" at a held-out level: the truth's own median |error| there (the
/// lab's scatter: per-drop bed spread, force fluctuations, sensor noise, the contact ramp) plus
/// twice the fitted law's own uncertainty there (LevelOutRow::*_law_sd_pct: the law is fitted on 48
/// noisy drops, and a 4 % error of phi moves the slow drops' tstop ~ 1/(phi - 1) by 10 %).
struct NoiseBound {
  double zstop_pct = 0, tstop_pct = 0;
};
NoiseBound noise_bound(const LevelOutRow& r, const Campaign& c, const std::string& truth, const SynthOptions& o) {
  const auto [nz, nt] = truth_noise_pct(c, truth, o, r.g_m_s2);
  const double uz = r.zstop_law_sd_pct, ut = r.tstop_law_sd_pct;
  std::printf("  g %g: truth's own median |error| zstop %.2f %%, tstop %.2f %%; law's sd %.2f %%, %.2f %%\n", r.g_m_s2,
              nz, nt, uz, ut);
  return {nz + 2 * uz, nt + 2 * ut};
}

constexpr unsigned kSeeds = 3;
const std::vector<double> kInnerLevels_m_s2{1.62, 0.1};

// A Froude-scaled truth (base: f0 = 1.6 m g, 1/d1 = 25 1/m at every level, i.e. R = m g F(v^2/(g D)))
// over four levels: scaled_base fitted on three levels predicts each inner held-out level (1.62 and
// 0.1 m/s2, inside the fitted range) within the noise bound above, in every seed (held-out zstop
// 7.8-11.6 % at 1.62 and 5.1-5.6 % at 0.1 m/s2, at most 0.82 of the bound).
TEST(LevelOut, AFroudeScaledTruthIsPredictedAtEachInnerHeldOutLevelWithinTheNoise) {
  for (unsigned seed = 1; seed <= kSeeds; ++seed) {
    TempDir d;
    const SynthOptions o = four_levels(seed);
    const Campaign c = synth_campaign("base", o, d);
    const auto rows = leave_level_out(parse_model("scaled_base"), c);
    ASSERT_EQ(rows.size(), 4u);
    print_rows(("froude-scaled seed " + std::to_string(seed)).c_str(), rows);
    EXPECT_FALSE(rows.front().inside);  // 9.81 and 0.01: extrapolations
    EXPECT_FALSE(rows.back().inside);
    EXPECT_EQ(rows.front().verdict.rfind("extrapolation", 0), 0u) << rows.front().verdict;
    for (double g : kInnerLevels_m_s2) {
      const LevelOutRow& r = row_at(rows, g);
      EXPECT_TRUE(r.inside) << g;
      EXPECT_EQ(r.trials, 16);
      const NoiseBound b = noise_bound(r, c, "base", o);
      EXPECT_LE(r.zstop_median_abs_err_pct, b.zstop_pct) << "seed " << seed << " g " << g;
      EXPECT_LE(r.tstop_median_abs_err_pct, b.tstop_pct) << "seed " << seed << " g " << g;
    }
  }
}

// The same lab with a hidden 0.5 N cohesion, a resistance that does not follow g: at 0.1 m/s2,
// where it is four times the projectile's weight, the law fitted on the other levels misses the
// held-out level far beyond the same noise bound and by at least three times the error of the
// Froude-scaled truth there (3 seeds: zstop 58-64 %, tstop 215-236 %, against 5-6 % and 7-17 %). At
// 1.62 m/s2 it is a quarter of the weight, and the law fitted on the levels about it predicts the
// level within the noise (zstop 8-11 %): held out, a level says less than the ranking of the
// scaled mode, which names the cohesion (test_model.cpp, Discovery).
TEST(LevelOut, AResistanceThatDoesNotFollowGravityIsMissedAtTheHeldOutLevelWhereItDominates) {
  constexpr double kCohesionDominates_m_s2 = 0.1;
  for (unsigned seed = 1; seed <= kSeeds; ++seed) {
    TempDir d_scaled, d_cohesion;
    const SynthOptions o = four_levels(seed);
    const auto scaled = leave_level_out(parse_model("scaled_base"), synth_campaign("base", o, d_scaled));
    const Campaign c = synth_campaign("base+cohesion", o, d_cohesion);
    const auto rows = leave_level_out(parse_model("scaled_base"), c);
    print_rows(("cohesion seed " + std::to_string(seed)).c_str(), rows);
    const LevelOutRow &r = row_at(rows, kCohesionDominates_m_s2), &froude = row_at(scaled, kCohesionDominates_m_s2);
    std::printf("  held-out zstop %.1f %% (Froude-scaled truth %.1f %%), tstop %.1f %% (%.1f %%)\n",
                r.zstop_median_abs_err_pct, froude.zstop_median_abs_err_pct, r.tstop_median_abs_err_pct,
                froude.tstop_median_abs_err_pct);
    const NoiseBound b = noise_bound(r, c, "base+cohesion", o);
    EXPECT_GT(r.zstop_median_abs_err_pct, b.zstop_pct) << "seed " << seed;
    EXPECT_GT(r.tstop_median_abs_err_pct, b.tstop_pct) << "seed " << seed;
    EXPECT_GT(r.zstop_median_abs_err_pct, 3 * froude.zstop_median_abs_err_pct) << "seed " << seed;
    EXPECT_GT(r.tstop_median_abs_err_pct, 3 * froude.tstop_median_abs_err_pct) << "seed " << seed;
    EXPECT_EQ(r.verdict.rfind("misses the targets", 0), 0u) << r.verdict;
  }
}

// A held-out level has no parameter of its own: a law with one per level is refused, and so is a
// campaign with a single level (nothing to fit on).
TEST(LevelOut, ALawWithAParameterPerLevelAndASingleLevelAreRefused) {
  TempDir d;
  SynthOptions o = four_levels(1);
  o.gravity_m_s2 = {9.81, 1.62};
  o.impact_speed_m_s = {0.3, 0.6, 0.9};
  const Campaign c = synth_campaign("base", o, d);
  EXPECT_THROW(leave_level_out(parse_model("base"), c), std::invalid_argument);
  EXPECT_THROW(leave_level_out(parse_model("scaled_base+depth_friction"), c), std::invalid_argument);
  EXPECT_NO_THROW(leave_level_out(parse_model("scaled_base+depth_friction:shared"), c));
  Campaign one = c;
  one.trials.erase(std::remove_if(one.trials.begin(), one.trials.end(),
                                  [](const MeasuredTrial& t) { return t.info.gravity_m_s2 < 5; }),
                   one.trials.end());
  EXPECT_THROW(leave_level_out(parse_model("scaled_base"), one), std::invalid_argument);
}

// The regime map of a law with known phi and d1: the inertial drag m v^2/d1 equals the quasi-static
// phi m g at v^2/d1 = phi g, i.e. Fr_c = v/sqrt(g D) = sqrt(phi d1 / D), the same at every level:
// 0.8 for the synthetic lab's truth (phi = 1.6, d1 = 1/25 m, D = 0.1 m).
TEST(Regimes, TheCrossoverOfAKnownTruthIsSqrtOfPhiD1OverD) {
  constexpr double kPhi = 1.6, kD1_m = 1.0 / 25.0, kD_m = 0.1;
  const double truth_fr = std::sqrt(kPhi * kD1_m / kD_m);
  TempDir d;
  const SynthOptions o = four_levels(3);
  const Campaign c = synth_campaign("base", o, d);
  // The truth itself (f0 = 1.6 m g and 1/d1 = 25 at each level): the analytic value, to the bisection.
  const FittedModel truth = truth_model(parse_model("base"), o.gravity_m_s2, o.mass_kg, o.diameter_m);
  for (const auto& t : c.trials)
    EXPECT_NEAR(surface_crossover_froude(truth, first_contact(t.info)), truth_fr, 1e-9) << t.info.gravity_m_s2;
  // The law fitted on the lab's noisy drops: within 3 standard errors of its crossover, propagated
  // from the cluster-robust covariance of phi and 1/d1 (Fr_c ~ sqrt(phi / (1/d1)): half their
  // relative errors); 3 % here, so the tolerance is about 10 %, and paper II's 1.5 lies far outside.
  const FittedModel law = fit_model(parse_model("scaled_base"), c);
  const double phi = law.coef(0), inv_d1 = law.coef(1);
  const double fit_fr = std::sqrt(phi / (inv_d1 * kD_m));
  const double se =
      0.5 * fit_fr *
      std::sqrt(law.cov(0, 0) / (phi * phi) + law.cov(1, 1) / (inv_d1 * inv_d1) - 2 * law.cov(0, 1) / (phi * inv_d1));
  std::printf("fitted phi %.4f, 1/d1 %.3f 1/m: crossover Fr %.4f +- %.4f (truth %.4f)\n", phi, inv_d1, fit_fr, se,
              truth_fr);
  EXPECT_LT(se, 0.05 * truth_fr);
  EXPECT_NEAR(fit_fr, truth_fr, 3 * se);
  const auto map = regime_map(law, c);
  ASSERT_EQ(map.size(), c.trials.size());
  int crossing = 0;
  for (const auto& r : map) {
    SCOPED_TRACE(c.trials[r.trial].info.trial_id);
    ASSERT_TRUE(r.stopped);
    EXPECT_NEAR(r.surface_crossover_froude, fit_fr, 1e-6 * fit_fr);
    // A drop faster than the crossover crosses it on the way down, at Fr_c whatever its depth (no
    // depth term); a slower one is quasi-static from the impact on.
    EXPECT_EQ(std::isfinite(r.crossover_froude), r.impact_froude > fit_fr) << r.impact_froude;
    if (std::isfinite(r.crossover_froude)) {
      ++crossing;
      EXPECT_NEAR(r.crossover_froude, fit_fr, 1e-4 * fit_fr);
    }
    // The shares balance the motion: the impulse of all the resistance is m (vc + g tstop), its
    // work (1/2) m vc^2 + m g zstop, and the quasi-static part is phi m g throughout.
    const Prediction p = predict(law, c.trials[r.trial].info);
    const double g = r.g_m_s2, vc = r.vc_m_s;
    EXPECT_NEAR(r.quasi_static_impulse_pct, 100 * phi * g * p.tstop_s / (vc + g * p.tstop_s), 0.2);
    EXPECT_NEAR(r.quasi_static_work_pct, 100 * phi * g * p.zstop_m / (0.5 * vc * vc + g * p.zstop_m), 0.2);
  }
  EXPECT_GT(crossing, 10);
  EXPECT_LT(crossing, static_cast<int>(map.size()));
}

}  // namespace
}  // namespace gravsweep::results

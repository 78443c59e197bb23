// The committed gravity sweep (data/gravity_sweep/, GRAVITY.md): the collapse, the leave-one-level-
// out law, the regime map and `model rank --scaled` on its five levels must keep giving the values
// GRAVITY.md states, so that a change to processing or fitting that moves them fails here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "results/io/csv.h"
#include "results/measurements/campaign.h"
#include "tests/common/temp_dir.h"
#include "results_helpers.h"

namespace {

/// The rows of `gravsweep <args> --format csv`, each by column name.
std::vector<std::map<std::string, std::string>> csv_rows(const std::string& args, std::string& out) {
  const auto r = gravsweep::testing::run_gravsweep(args + " --format csv", false);
  out = r.out;
  std::vector<std::map<std::string, std::string>> rows;
  if (r.code != 0) return rows;
  std::istringstream in(r.out);
  gravsweep::results::CsvReader csv(in);
  std::vector<std::string> header, cells;
  int line = 0;
  csv.next(header, line);
  while (csv.next(cells, line)) {
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) row[header[i]] = cells[i];
    rows.push_back(row);
  }
  return rows;
}

/// One committed folder of the gravity sweep as a quoted command-line argument, with a space before.
std::string level_folder(const char* level) {
  return " '" + (std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "data" / "gravity_sweep" / level).string() + "'";
}

/// The eight committed folders of the gravity sweep: five levels, 50 drops (GRAVITY.md).
std::string sweep_levels() {
  std::string s;
  for (const char* level : {"g9.81", "g1.62", "g0.1", "g0.1_axis", "g0.01", "g0.01_axis", "g0.001", "g0.001_axis"})
    s += level_folder(level);
  return s;
}

}  // namespace

// The gravity sweep's committed levels (data/gravity_sweep/, GRAVITY.md), recomputed from the
// traces, and the level effect at equal Fr (nested ANOVA over the 25 cells of Froude number and
// level, two repeats each). Processed in each drop's own scales (the default of DEM drops) all
// three scaled metrics collapse: the levels differ by no more than the repeats (p >= 0.01). In the
// paper's fixed hertz and seconds the duration and the peak "did not collapse": that was the
// 500 Hz filter, ten to a hundred times wider in units of sqrt(g/D) below 1 g.
TEST(GravitySweep, TheCommittedLevelsCollapseInAllThreeMetricsInTheirOwnScales) {
  std::string out;
  auto by_metric = [&](const std::string& extra) {
    std::map<std::string, std::map<std::string, std::string>> m;
    for (const auto& r : csv_rows("model collapse" + sweep_levels() + extra, out)) m[r.at("metric")] = r;
    std::printf("%s", out.c_str());
    return m;
  };
  auto own = by_metric("");
  ASSERT_EQ(own.size(), 3u) << out;
  for (const auto& [metric, r] : own) {
    SCOPED_TRACE(metric);
    EXPECT_EQ(r.at("trials"), "50");
    EXPECT_EQ(r.at("cells"), "25");
    EXPECT_GE(std::stod(r.at("level_p")), 0.01);
    EXPECT_EQ(r.at("verdict").rfind("collapses", 0), 0u) << r.at("verdict");
  }
  EXPECT_NEAR(std::stod(own["zstop_over_D"].at("level_p")), 0.033, 0.005);
  EXPECT_NEAR(std::stod(own["tstop_sqrt_g_over_D"].at("level_p")), 0.14, 0.02);
  EXPECT_NEAR(std::stod(own["tstop_sqrt_g_over_D"].at("repeat_scatter_pct")), 3.7, 0.3);
  EXPECT_NEAR(std::stod(own["tstop_sqrt_g_over_D"].at("collapse_ratio")), 1.01, 0.05);
  EXPECT_NEAR(std::stod(own["apeak_over_g"].at("level_p")), 0.59, 0.05);
  auto fixed = by_metric(" --time-scale fixed");
  ASSERT_EQ(fixed.size(), 3u) << out;
  EXPECT_LT(std::stod(fixed["tstop_sqrt_g_over_D"].at("level_p")), 0.01);
  EXPECT_NEAR(std::stod(fixed["tstop_sqrt_g_over_D"].at("collapse_ratio")), 1.55, 0.05);
  EXPECT_LT(std::stod(fixed["apeak_over_g"].at("level_p")), 1e-9);
  EXPECT_GT(std::stod(fixed["apeak_over_g"].at("level_scatter_pct")), 100);
  // The depth does not depend on the filter: the same under both.
  EXPECT_EQ(fixed["zstop_over_D"].at("level_p"), own["zstop_over_D"].at("level_p"));
}

// Leave one level out on the five committed levels (GRAVITY.md, "One gravity-scaled law"): phi m g
// + kappa g z + m v^2/d1 fitted on four levels predicts the fifth's duration within 2-9 % at every
// level, and misses its depth by 12-20 % at every level as much as when the level is in the fit:
// the form misses, not the gravity scaling. The signed errors by Froude number show how: too
// shallow at Fr 0.2 at every level, too deep at Fr 1-2. Without the depth term every level is
// missed by more than 30 % in zstop.
TEST(GravitySweep, OneDepthFrictionLawPredictsEachHeldOutLevelAsWellAsWithTheLevelInTheFit) {
  std::string out;
  const std::string law = " --law scaled_base+gravity_depth_friction";
  const auto rows = csv_rows("model lolo" + sweep_levels() + law, out);
  std::printf("%s", out.c_str());
  ASSERT_EQ(rows.size(), 5u) << out;
  const std::map<std::string, std::pair<double, double>> stated{{"9.81", {19.0, 8.3}},
                                                                {"1.62", {18.5, 2.3}},
                                                                {"0.1", {12.0, 5.4}},
                                                                {"0.01", {19.5, 3.8}},
                                                                {"0.001", {18.3, 8.6}}};
  for (const auto& r : rows) {
    const std::string g = r.at("held_out_g_m_s2");
    SCOPED_TRACE(g);
    ASSERT_EQ(stated.count(g), 1u);
    EXPECT_NEAR(std::stod(r.at("zstop_median_err_pct")), stated.at(g).first, 1.0);
    EXPECT_NEAR(std::stod(r.at("tstop_median_err_pct")), stated.at(g).second, 1.0);
    EXPECT_NEAR(std::stod(r.at("zstop_all_levels_err_pct")), std::stod(r.at("zstop_median_err_pct")), 2.0);
    EXPECT_EQ(r.at("range"), g == "9.81" || g == "0.001" ? "outside" : "inside");
    EXPECT_NE(r.at("verdict").find("the form of the law misses this level even with it in the fit"), std::string::npos)
        << r.at("verdict");
    EXPECT_NE(r.at("verdict").find("beyond a target at Fr 0.2 (zstop -"), std::string::npos) << r.at("verdict");
  }
  const auto by_froude = csv_rows("model lolo" + sweep_levels() + law + " --per-froude", out);
  ASSERT_EQ(by_froude.size(), 25u) << out;
  for (const auto& r : by_froude) {
    const double fr = std::stod(r.at("impact_fr")), z = std::stod(r.at("zstop_mean_err_pct"));
    if (fr < 0.3) {
      EXPECT_LT(z, -10) << r.at("held_out_g_m_s2");
    }
    if (fr > 0.8 && fr < 3) {
      EXPECT_GT(z, 10) << r.at("held_out_g_m_s2") << " Fr " << fr;
    }
  }
  const auto plain = csv_rows("model lolo" + sweep_levels(), out);
  ASSERT_EQ(plain.size(), 5u) << out;
  for (const auto& r : plain) EXPECT_GT(std::stod(r.at("zstop_median_err_pct")), 30.0) << r.at("held_out_g_m_s2");
}

// The regime map of the depth-friction law fitted on all five levels, and the crossover by three
// definitions: the drag equals the quasi-static resistance at the surface at Fr 0.69 at every
// level, does half the work of a whole collision at Fr 1.44 and carries half its impulse at Fr
// 2.63: paper II's ~1.5 is the energy definition. A drop that starts above the surface crossover
// crosses it on its way down, one that starts below is quasi-static from the impact on.
TEST(GravitySweep, TheCrossoverOfTheFiveLevelsByThreeDefinitions) {
  std::string out;
  const auto rows = csv_rows("model regimes" + sweep_levels() + " --law scaled_base+gravity_depth_friction", out);
  std::printf("%s", out.c_str());
  ASSERT_EQ(rows.size(), 50u) << out;
  for (const auto& r : rows) {
    SCOPED_TRACE(r.at("trial_id"));
    const double crossover = std::stod(r.at("law_crossover_fr"));
    EXPECT_NEAR(crossover, 0.693, 0.005);
    EXPECT_EQ(r.at("paper_ii_fr"), "1.5");
    EXPECT_EQ(r.at("crossover_fr") != "-", std::stod(r.at("impact_fr")) > crossover) << r.at("impact_fr");
  }
  const auto table = gravsweep::testing::run_gravsweep(
      "model regimes" + sweep_levels() + " --law scaled_base+gravity_depth_friction", false);
  EXPECT_NE(table.out.find("the drag does half the work at Fr 1.44 +- 0.038 and carries half the impulse at Fr 2.63"),
            std::string::npos)
      << table.out;
}

// `model rank --scaled` on the five levels names the depth friction that follows g (held-out
// trace error down 25 %, better on 46 of 50 drops); no generated form is significant.
TEST(GravitySweep, TheScaledRankOnTheFiveLevelsNamesTheDepthFrictionThatFollowsGravity) {
  const auto r = gravsweep::testing::run_gravsweep("model rank" + sweep_levels() + " --scaled", false);
  ASSERT_EQ(r.code, 0) << r.out;
  std::printf("%s", r.out.c_str());
  EXPECT_NE(r.out.find("Verdict: missing effect: gravity_depth_friction ("), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("better on 46 of 50 trials"), std::string::npos) << r.out;
  // Then the linear drag in its Froude-scaled form (tried since the scaled mode tries each term's
  // Froude power), or equally well the drag of immersion.
  EXPECT_NE(r.out.find("; then viscous_drag:g^0.5 ("), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("or equally well immersion_drag:shared"), std::string::npos) << r.out;
}

// At 0.001 m/s2 and Fr 10, processed in the paper's fixed hertz and seconds, the collision "ended"
// at 84-86 % of the maximum depth, the projectile still moving at 0.1 vc (it sank 16-18 mm more):
// a 500 Hz filter passes the grain contacts of a projectile at rest. In the drop's own scales the
// collision ends at its maximum depth (at least 97 % of it).
TEST(GravitySweep, AtOneThousandthGTheFroudeTenCollisionEndsAtItsMaximumDepth) {
  using namespace gravsweep::results;
  const auto folder = std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "data" / "gravity_sweep" / "g0.001";
  Campaign c = load_campaign(folder.string());
  auto fraction_at_end = [&](const char* time_scale) {
    reprocess_campaign(c, {time_scale, ""});
    std::vector<double> f;
    for (const auto& t : c.trials) {
      const auto& m = t.processed.metrics;
      if (m.vc_m_s / std::sqrt(t.info.gravity_m_s2 * t.info.projectile_diameter_m) > 8)
        f.push_back(m.depth_at_end_m / m.zstop_m);
    }
    return f;
  };
  const auto fixed = fraction_at_end("fixed");
  ASSERT_EQ(fixed.size(), 2u);
  for (double f : fixed) EXPECT_LT(f, 0.9) << "the fixed processing ends the collision early";
  const auto own = fraction_at_end("froude");
  ASSERT_EQ(own.size(), 2u);
  for (double f : own) EXPECT_GE(f, 0.97);
  std::printf("depth at the end / zstop: fixed %.3f %.3f, own scales %.3f %.3f\n", fixed[0], fixed[1], own[0], own[1]);
}

// The law's constants depend on the Froude range it is fitted on (GRAVITY.md): on Fr <= 1 alone
// and on Fr >= 2 alone phi is 0.61 and 1.93, many standard errors apart (`--where
// 'impact_froude...'`, a trial's vc / sqrt(g D)).
TEST(GravitySweep, TheLawsConstantsDependOnTheFroudeRangeItIsFittedOn) {
  const gravsweep::test::TempDir tmp;
  auto phi = [&](const char* where, double& se) {
    std::string out;
    const auto rows = csv_rows("model fit" + sweep_levels() + " --model scaled_base+gravity_depth_friction --where '" +
                                   where + "' --plot '" + (tmp.path / "error_falls.png").string() + "'",
                               out);
    for (const auto& r : rows)
      if (r.count("parameter") && r.at("parameter") == "scaled_base.phi") {
        se = std::stod(r.at("std_error"));
        return std::stod(r.at("value"));
      }
    ADD_FAILURE() << out;
    return 0.0;
  };
  double se_low = 0, se_high = 0;
  const double low = phi("impact_froude<=1.1", se_low), high = phi("impact_froude>=1.5", se_high);
  EXPECT_NEAR(low, 0.605, 0.01);
  EXPECT_NEAR(high, 1.93, 0.02);
  EXPECT_GT(high - low, 5 * std::hypot(se_low, se_high));
}

// Fr 2 and 3 at 9.81 m/s2 (g9.81_fast/): with them every level reaches above Fr 1, and the drops
// at Fr >= 2 of all five levels collapse (no level effect, p >= 0.01, in all three metrics). Their
// step: the same drops at 2.5 us on the same sites move zstop by under 0.5 %
// (dt_check_9.81_fast.csv).
TEST(GravitySweep, AboveFroudeOneTheFiveLevelsCollapseAndTheStepHoldsAtThreeMetresPerSecond) {
  std::string out;
  const auto rows =
      csv_rows("model collapse" + sweep_levels() + level_folder("g9.81_fast") + " --where 'impact_froude>=1.5'", out);
  std::printf("%s", out.c_str());
  ASSERT_EQ(rows.size(), 3u) << out;
  for (const auto& r : rows) {
    SCOPED_TRACE(r.at("metric"));
    EXPECT_EQ(r.at("levels"), "5");
    EXPECT_EQ(r.at("trials"), "24");
    EXPECT_GE(std::stod(r.at("level_p")), 0.01);
  }
  std::ifstream in(std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "data" / "gravity_sweep" / "dt_check_9.81_fast.csv");
  ASSERT_TRUE(in.good());
  gravsweep::results::CsvReader csv(in);
  std::vector<std::string> header, cells;
  int line = 0;
  ASSERT_TRUE(csv.next(header, line));
  auto col = [&](const char* name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  std::map<std::pair<std::string, std::string>, std::map<std::string, double>> by_site;  // (speed, seed) -> dt -> zstop
  while (csv.next(cells, line))
    by_site[{cells.at(col("impact_speed_m_s")), cells.at(col("projectile_seed"))}][cells.at(col("dt_s"))] =
        std::stod(cells.at(col("zstop_m")));
  ASSERT_EQ(by_site.size(), 4u);
  for (const auto& [site, z] : by_site) {
    ASSERT_EQ(z.size(), 2u);
    const double fine = z.begin()->second, coarse = z.rbegin()->second;  // "2.5e-06" sorts before "5e-06"
    EXPECT_NEAR(coarse / fine, 1.0, 0.005) << site.first << " m/s, seed " << site.second;
  }
}

namespace {

/// A committed folder of the gravity sweep (data/gravity_sweep/<folder>).
std::string sweep_folder(const char* folder) {
  return (std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "data" / "gravity_sweep" / folder).string();
}

/// Mean of a metric (m) of a folder's drops at each design Froude number (rounded to 0.1),
/// processed in the drops' own scales: zstop from the first contact by default, or from the bed's
/// mean surface (Metrics::zstop_surface_m).
std::map<double, double> zstop_by_froude(
    const std::vector<const char*>& folders,
    double gravsweep::results::Metrics::*depth = &gravsweep::results::Metrics::zstop_m) {
  using namespace gravsweep::results;
  std::map<double, std::vector<double>> z;
  for (const char* f : folders) {
    Campaign c = load_campaign(sweep_folder(f));
    reprocess_campaign(c, {"froude", ""});
    for (const auto& t : c.trials) {
      const double fr = t.processed.metrics.vc_m_s / std::sqrt(t.info.gravity_m_s2 * t.info.projectile_diameter_m);
      z[std::round(fr * 10) / 10].push_back(t.processed.metrics.*depth);
    }
  }
  std::map<double, double> mean;
  for (const auto& [fr, v] : z) {
    double s = 0;
    for (double x : v) s += x;
    mean[fr] = s / static_cast<double>(v.size());
  }
  return mean;
}

/// The deep bed's eight folders (GRAVITY.md, "Confinement, Fr 2 to 10"): one per export.
const std::vector<const char*> kDeepBed{
    "g0.01_deep",           "g0.01_deep_fr10",      "g0.01_deep_fr2_3",     "g0.01_deep_fr10_site2",
    "g0.01_deep_fr2_site3", "g0.01_deep_fr2_site4", "g0.01_deep_fr3_site3", "g0.01_deep_fr3_site4"};

/// A fitted constant of `gravsweep model fit ... --format csv`: {value, standard error}.
std::pair<double, double> fitted(const std::vector<std::map<std::string, std::string>>& rows, const std::string& name) {
  for (const auto& r : rows)
    if (r.count("parameter") && r.at("parameter") == name)
      return {std::stod(r.at("value")), std::stod(r.at("std_error"))};
  ADD_FAILURE() << "no fitted " << name;
  return {0, 1};
}

/// Fits the scaled law on the five levels' 21 cm beds and saves it in `dir` (`model fit --save`,
/// 30 bootstrap resamples); returns the law file's path, for `model predict --law`.
std::string fitted_sweep_law(const std::filesystem::path& dir) {
  const std::string law = (dir / "law.json").string();
  std::string out;
  csv_rows("model fit" + sweep_levels() + " --model scaled_base+gravity_depth_friction --resamples 30 --plot '" +
               (dir / "error_falls.png").string() + "' --save '" + law + "'",
           out);
  return law;
}

/// Every drop of a deep-bed folder stops at least 2 D above the floor (the fill height is the
/// floor's depth below the surface). From the wall they stay 1.9 D or more by design: the 26 cm
/// radius less the projectile's 5 cm and a site within two grain diameters of the axis.
void expect_two_diameters_above_the_floor(const char* folder) {
  using namespace gravsweep::results;
  Campaign c = load_campaign(sweep_folder(folder));
  reprocess_campaign(c, {"froude", ""});
  ASSERT_FALSE(c.trials.empty()) << folder;
  for (const auto& t : c.trials)
    EXPECT_GE((t.info.fill_height_m - t.processed.metrics.zstop_m) / t.info.projectile_diameter_m, 2.0)
        << folder << " " << t.info.trial_id;
}

}  // namespace

// Beds poured at the target gravity against the ramped beds (GRAVITY.md, "Beds poured at the
// target gravity"): at Fr 1 and 5 the depths agree within 5 % at 0.1 and 0.01 m/s2; at Fr 0.5 and
// 0.1 m/s2 the poured bed stops the projectile about 11 % shallower.
TEST(GravitySweep, BedsPouredAtTheirGravityGiveTheRampedBedsDepthsAtFroudeOneAndAbove) {
  const auto ramped_01 = zstop_by_froude({"g0.1", "g0.1_axis"}), poured_01 = zstop_by_froude({"g0.1_poured"});
  const auto ramped_001 = zstop_by_froude({"g0.01", "g0.01_axis"}), poured_001 = zstop_by_froude({"g0.01_poured"});
  ASSERT_EQ(poured_01.size(), 3u);
  ASSERT_EQ(poured_001.size(), 2u) << "Fr 0.5 on the poured 0.01 m/s2 bed is refused by the at-rest check";
  for (double fr : {1.0, 5.0}) {
    const double d01 = poured_01.at(fr) / ramped_01.at(fr) - 1, d001 = poured_001.at(fr) / ramped_001.at(fr) - 1;
    std::printf("Fr %.0f: poured / ramped - 1 = %+.1f %% at 0.1 m/s2, %+.1f %% at 0.01 m/s2\n", fr, 100 * d01,
                100 * d001);
    EXPECT_LT(std::abs(d01), 0.05);
    EXPECT_LT(std::abs(d001), 0.05);
  }
  const double d05 = poured_01.at(0.5) / ramped_01.at(0.5) - 1;
  std::printf("Fr 0.5 at 0.1 m/s2: %+.1f %%\n", 100 * d05);
  EXPECT_LT(d05, -0.08);
  EXPECT_GT(d05, -0.15);
}

// A second pour at 0.01 m/s2 (bed seed 2, GRAVITY.md "A second bed") against the sweep's bed: at
// Fr 1 and 5 the depths differ by less than the first bed's spread between its two impact sites
// (7 % at Fr 1), so the bed-to-bed scatter is of the order of the site-to-site one; Fr 0.5 is
// refused by the at-rest check on the second bed.
TEST(GravitySweep, ASecondBedAtOneHundredthGStopsTheProjectileWithinTheSiteSpread) {
  const auto first = zstop_by_froude({"g0.01"}), second = zstop_by_froude({"g0.01_bed2_relaxed"});
  ASSERT_EQ(second.size(), 2u) << "Fr 1 and 5 (Fr 0.5 refused at rest)";
  const double d1 = second.at(1.0) / first.at(1.0) - 1, d5 = second.at(5.0) / first.at(5.0) - 1;
  std::printf("second bed / first - 1 in zstop: %+.1f %% at Fr 1, %+.1f %% at Fr 5\n", 100 * d1, 100 * d5);
  EXPECT_LT(std::abs(d1), 0.08);
  EXPECT_LT(std::abs(d5), 0.03);
}

// The confinement check at 0.01 m/s2 (GRAVITY.md, "Confinement"): the same level in a 52 cm
// container filled to 34 cm, where the Fr 5 projectile stops about 2.5 D above the floor and 2 D
// from the wall (1.27 D and 1 D on the sweep's 21 cm bed in the 31.5 cm container). It sinks about
// 11 % deeper than on the sweep's bed, far beyond the spread of sites (1 %) and of beds (a second
// pour and a poured bed: 1-2 %): the small container's floor and wall hold the projectile up at
// Fr 5. The law's Fr 5 zstop miss (deeper than the 21 cm bed's drops) is that confinement.
TEST(GravitySweep, ADeeperWiderBedLetsTheFroudeFiveProjectileSinkDeeperThanAnyBedOrSiteSpread) {
  const auto sweep = zstop_by_froude({"g0.01"}), deep = zstop_by_froude({"g0.01_deep"});
  const auto second = zstop_by_froude({"g0.01_bed2_relaxed"}), poured = zstop_by_froude({"g0.01_poured"});
  ASSERT_TRUE(deep.count(5.0)) << "the deep bed's Fr 5 drops";
  const double d_deep = deep.at(5.0) / sweep.at(5.0) - 1;
  const double d_second = second.at(5.0) / sweep.at(5.0) - 1, d_poured = poured.at(5.0) / sweep.at(5.0) - 1;
  std::printf("Fr 5 zstop / the sweep's bed - 1: deep %+.1f %%, second pour %+.1f %%, poured %+.1f %%\n", 100 * d_deep,
              100 * d_second, 100 * d_poured);
  EXPECT_GT(d_deep, 0.07);
  EXPECT_LT(d_deep, 0.15);
  EXPECT_GT(d_deep, 3 * std::max(std::abs(d_second), std::abs(d_poured)));
  expect_two_diameters_above_the_floor("g0.01_deep");
}

// The same deep bed at Fr 10 (GRAVITY.md, "Confinement, Fr 2 to 10"): on the sweep's 21 cm bed
// the projectile stops under 1 D above the floor, on the deep bed 2 D above it, and sinks about a
// fifth deeper, several times the two sites' spread (2.5 %). The scaled law fitted on the 21 cm
// beds lies a few % deep of the confined drops but falls short of the unconfined one, beyond 10 %.
TEST(GravitySweep, AtFroudeTenTheDeepBedLetsTheProjectileSinkAFifthDeeperAndTheLawFallsShort) {
  const auto sweep = zstop_by_froude({"g0.01"}), deep = zstop_by_froude({"g0.01_deep_fr10"});
  ASSERT_TRUE(deep.count(10.0) && sweep.count(10.0)) << "Fr 10 on both beds";
  const double d_deep = deep.at(10.0) / sweep.at(10.0) - 1;
  std::printf("Fr 10 zstop: deep %.1f mm, the sweep's bed %.1f mm: %+.1f %%\n", 1e3 * deep.at(10.0),
              1e3 * sweep.at(10.0), 100 * d_deep);
  EXPECT_GT(d_deep, 0.15);
  EXPECT_LT(d_deep, 0.26);
  expect_two_diameters_above_the_floor("g0.01_deep_fr10");

  // The law fitted on the five levels' 21 cm beds, applied to this drop (`model predict`).
  const gravsweep::test::TempDir tmp;
  const std::string law = fitted_sweep_law(tmp.path);
  std::string out;
  const auto rows = csv_rows("model predict --law '" + law + "' --gravity 0.01 --speed 0.316228", out);
  ASSERT_EQ(rows.size(), 1u) << out;
  const double law_zstop_m = std::stod(rows[0].at("zstop_m"));
  std::printf("Fr 10 zstop: the law %.1f mm\n", 1e3 * law_zstop_m);
  EXPECT_GT(law_zstop_m, sweep.at(10.0)) << "deep of the confined drops";
  EXPECT_LT(law_zstop_m, 0.9 * deep.at(10.0)) << "short of the unconfined drop by more than 10 %";
}

// The deep bed from Fr 2 to 10 (GRAVITY.md, "Confinement, Fr 2 to 10"): the shift in zstop against
// the sweep's 21 cm bed grows as the floor comes nearer the stop (1.6 D at Fr 2, 1.3 D at Fr 5,
// under 1 D at Fr 10), from the first contact and from the bed's mean surface alike. At Fr 2 it
// depends on the reference (the deep bed's sites stand 4 mm above its mean surface); at Fr 10 it
// is a sixth or more by either.
TEST(GravitySweep, TheDeepBedsShiftGrowsAsTheFloorNearsTheStop) {
  using gravsweep::results::Metrics;
  for (auto depth : {&Metrics::zstop_m, &Metrics::zstop_surface_m}) {
    const auto sweep = zstop_by_froude({"g0.01"}, depth), deep = zstop_by_froude(kDeepBed, depth);
    ASSERT_TRUE(deep.count(2.0) && deep.count(3.0) && deep.count(5.0) && deep.count(10.0)) << "Fr 2, 3, 5, 10";
    const double d2 = deep.at(2.0) / sweep.at(2.0) - 1, d5 = deep.at(5.0) / sweep.at(5.0) - 1,
                 d10 = deep.at(10.0) / sweep.at(10.0) - 1;
    std::printf("deep / sweep's bed - 1 (%s): Fr 2 %+.1f %%, Fr 5 %+.1f %%, Fr 10 %+.1f %%\n",
                depth == &Metrics::zstop_m ? "from the first contact" : "from the mean surface", 100 * d2, 100 * d5,
                100 * d10);
    EXPECT_LT(d2, d5);
    EXPECT_LT(d5, d10);
    EXPECT_GT(d2, -0.02);
    EXPECT_LT(d2, 0.12);
    EXPECT_GT(d10, 0.15);
  }
  expect_two_diameters_above_the_floor("g0.01_deep_fr2_3");
}

// The law on an unconfined bed (GRAVITY.md, "Confinement, Fr 2 to 10"): fitted on the 21 cm beds
// of the five levels, it is deep of the deep bed's drops at Fr 2 and 3 and short at Fr 10, its error
// falling along Fr: the misses by Froude number are its form. Fitted on each bed's drops of Fr 2-10
// at 0.01 m/s2, the container leaves phi and kappa within their errors and raises 1/d1 (the drag).
TEST(GravitySweep, OnTheDeepBedTheLawsErrorChangesSignAlongFroudeAndTheContainerMovesTheDrag) {
  const auto deep = zstop_by_froude(kDeepBed);
  const gravsweep::test::TempDir tmp;
  const std::string law = fitted_sweep_law(tmp.path);
  std::string out;
  const auto rows =
      csv_rows("model predict --law '" + law + "' --gravity 0.01 --speed 0.063246 0.094868 0.158114 0.316228", out);
  ASSERT_EQ(rows.size(), 4u) << out;
  double previous = 1e9;
  for (const auto& r : rows) {
    const double fr = std::round(std::stod(r.at("impact_froude")) * 10) / 10;
    ASSERT_TRUE(deep.count(fr)) << "Fr " << fr;
    const double err = std::stod(r.at("zstop_m")) / deep.at(fr) - 1;
    std::printf("Fr %.0f: the law %+.1f %% of the deep bed\n", fr, 100 * err);
    EXPECT_LT(err, previous) << "Fr " << fr;
    previous = err;
    if (fr <= 3) {
      EXPECT_GT(err, 0.05) << "Fr " << fr;
    }
    if (fr >= 10) {
      EXPECT_LT(err, -0.10) << "Fr " << fr;
    }
  }

  std::string deep_folders;
  for (const char* f : kDeepBed) deep_folders += level_folder(f);
  const std::string model = " --model scaled_base+gravity_depth_friction --no-plot";
  const auto unconfined = csv_rows("model fit" + deep_folders + model, out);
  const auto confined = csv_rows(
      "model fit" + level_folder("g0.01") + level_folder("g0.01_axis") + " --where 'impact_froude>=1.9'" + model, out);
  for (const char* name : {"scaled_base.phi", "gravity_depth_friction.kappa_kg_m", "scaled_base.inv_d1_1_m"}) {
    const auto [u, su] = fitted(unconfined, name);
    const auto [c, sc] = fitted(confined, name);
    const double z = (c - u) / std::hypot(su, sc);
    std::printf("%s: deep bed %.3g +- %.2g, 21 cm bed %.3g +- %.2g: %.1f SE\n", name, u, su, c, sc, z);
    if (std::string(name) == "scaled_base.inv_d1_1_m") {
      EXPECT_GT(z, 2.5) << "the container raises the drag";
    } else {
      EXPECT_LT(std::abs(z), 2.0) << name;
    }
  }
}

// At 0.01 m/s2 the traces of both beds (the 21 cm drops and the deep bed's) name a drag linear in
// the speed as the missing term (held-out trace error down 9 %, better on 20 of 24 drops,
// p = 0.0019 against the 0.002 five candidates need). With one constant b for all levels it is a
// term of the traces, not of the zstop misses along Fr: added to the law fitted on the five levels'
// 21 cm beds it moves the law's zstop at Fr 2 and 10 by under 3 %, so the law still errs deep at
// Fr 2 and short at Fr 10 on the deep bed (Froude-scaled, it does not: the next test).
TEST(GravitySweep, AtOneHundredthGTheTracesNameALinearDragThatLeavesTheMissesAlongFroude) {
  std::string folders;
  for (const char* f : kDeepBed) folders += level_folder(f);
  const auto r =
      gravsweep::testing::run_gravsweep("model rank" + folders + level_folder("g0.01") + level_folder("g0.01_axis") +
                                            " --baseline scaled_base+gravity_depth_friction",
                                        false);
  ASSERT_EQ(r.code, 0) << r.out;
  std::printf("%s", r.out.c_str());
  EXPECT_NE(r.out.find("Verdict: missing effect: viscous_drag ("), std::string::npos) << r.out;

  const gravsweep::test::TempDir tmp;
  const auto deep = zstop_by_froude(kDeepBed);
  auto law_zstop = [&](const std::string& model, const char* name) {
    const std::string law = (tmp.path / name).string();
    std::string out;
    csv_rows("model fit" + sweep_levels() + " --model " + model + " --resamples 30 --no-plot --save '" + law + "'",
             out);
    const auto rows = csv_rows("model predict --law '" + law + "' --gravity 0.01 --speed 0.063246 0.316228", out);
    EXPECT_EQ(rows.size(), 2u) << out;
    std::map<double, double> z;
    for (const auto& row : rows) z[std::round(std::stod(row.at("impact_froude")))] = std::stod(row.at("zstop_m"));
    return z;
  };
  const auto without = law_zstop("scaled_base+gravity_depth_friction", "law.json");
  const auto with = law_zstop("scaled_base+gravity_depth_friction+viscous_drag", "law_drag.json");
  for (const double fr : {2.0, 10.0}) {
    ASSERT_TRUE(without.count(fr) && with.count(fr) && deep.count(fr)) << "Fr " << fr;
    std::printf("Fr %.0f: the law %.1f mm, with the linear drag %.1f mm, the deep bed %.1f mm\n", fr,
                1e3 * without.at(fr), 1e3 * with.at(fr), 1e3 * deep.at(fr));
    EXPECT_LT(std::abs(with.at(fr) / without.at(fr) - 1), 0.03) << "Fr " << fr;
  }
  EXPECT_GT(with.at(2.0) / deep.at(2.0) - 1, 0.05) << "still deep at Fr 2";
  EXPECT_LT(with.at(10.0) / deep.at(10.0) - 1, -0.05) << "still short at Fr 10";
}

// The linear drag in its Froude-scaled form, b v with b = b' m sqrt(g / D) (`viscous_drag:g^0.5`,
// its constant carried by g^0.5 so that its force goes as m g at equal Froude number), fitted on
// the sweep's 50 drops of the 21 cm beds: the misses along Fr shrink at every level, held out, and
// on the unconfined deep bed the sign change along Fr nearly goes (GRAVITY.md, "A linear drag that
// follows the Froude scaling"). With one b for all levels the same term does nothing (above): at
// equal Froude number b v is sqrt(9.81 / 0.001) = 99 times weaker against m g at 9.81 m/s2.
TEST(GravitySweep, AFroudeScaledLinearDragTakesOutMostOfTheMissesAlongFroude) {
  std::string out;
  const std::string law = "scaled_base+gravity_depth_friction";
  const std::string drag = law + "+viscous_drag:g^0.5";
  auto worst_cell = [&](const std::string& model, double& fr_low_min, double& fr_high_max) {
    const auto rows = csv_rows("model lolo" + sweep_levels() + " --law " + model + " --per-froude", out);
    EXPECT_EQ(rows.size(), 25u) << out;
    fr_low_min = 0, fr_high_max = 0;
    for (const auto& r : rows) {
      const double fr = std::stod(r.at("impact_fr")), z = std::stod(r.at("zstop_mean_err_pct"));
      if (fr < 0.3) fr_low_min = std::min(fr_low_min, z);
      if (fr > 0.8) fr_high_max = std::max(fr_high_max, z);
    }
  };
  double low_without = 0, high_without = 0, low_with = 0, high_with = 0;
  worst_cell(law, low_without, high_without);
  worst_cell(drag, low_with, high_with);
  std::printf(
      "held out, signed zstop error: Fr 0.2 down to %.1f %% (%.1f %% with the drag), Fr >= 1 up to %.1f %% "
      "(%.1f %%)\n",
      low_without, low_with, high_without, high_with);
  EXPECT_LT(low_without, -25.0);
  EXPECT_GT(high_without, 25.0);
  EXPECT_GT(low_with, -15.0);
  EXPECT_LT(high_with, 15.0);

  const gravsweep::test::TempDir tmp;
  const auto deep = zstop_by_froude(kDeepBed);
  auto errors = [&](const std::string& model, const char* name) {
    const std::string file = (tmp.path / name).string();
    csv_rows("model fit" + sweep_levels() + " --model " + model + " --resamples 30 --no-plot --save '" + file + "'",
             out);
    const auto rows =
        csv_rows("model predict --law '" + file + "' --gravity 0.01 --speed 0.063246 0.094868 0.158114 0.316228", out);
    EXPECT_EQ(rows.size(), 4u) << out;
    std::map<double, double> e;
    for (const auto& row : rows) {
      const double fr = std::round(std::stod(row.at("impact_froude")));
      e[fr] = deep.count(fr) ? std::stod(row.at("zstop_m")) / deep.at(fr) - 1 : NAN;
    }
    return e;
  };
  const auto without = errors(law, "law.json"), with = errors(drag, "law_drag.json");
  double span_without = 0, span_with = 0;
  for (const double fr : {2.0, 3.0, 5.0}) {
    ASSERT_TRUE(without.count(fr) && with.count(fr)) << "Fr " << fr;
    std::printf("deep bed, Fr %.0f: the law %+.1f %%, with the drag %+.1f %%\n", fr, 100 * without.at(fr),
                100 * with.at(fr));
    EXPECT_LT(std::abs(with.at(fr)), 0.05) << "Fr " << fr;
    span_without = std::max(span_without, without.at(fr) - without.at(10.0));
    span_with = std::max(span_with, with.at(fr) - with.at(10.0));
  }
  std::printf("deep bed, Fr 10: the law %+.1f %%, with the drag %+.1f %%\n", 100 * without.at(10.0),
              100 * with.at(10.0));
  EXPECT_GT(span_without, 0.2);  // +13 % at Fr 2 to -12 % at Fr 10
  EXPECT_LT(span_with, 0.13);    // +3 % to -8 %
}

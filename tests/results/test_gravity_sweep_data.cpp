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
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gravity_sweep_helpers.h"
#include "tests/common/temp_dir.h"

using namespace gravsweep::testing::sweep;

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
// 2.63 (with the Froude-scaled linear drag, below: 0.35, 0.86, 1.77; paper II's ~1.5 lies between
// the whole-collision definitions under either law). A drop that starts above the surface
// crossover crosses it on its way down, one that starts below is quasi-static from the impact on.
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
  EXPECT_NE(table.out.find("Fr 0.693 +- 0.023 by the law at the surface"), std::string::npos) << table.out;
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

// data/gravity_sweep/results.csv is every committed drop in one table with one definition: its
// metrics are the processing of the committed traces (each drop in its own scales), so a change
// to the processing that is not followed by `deploy/gravity-sweep.sh table` fails here, and so
// does a folder left out of the table.
TEST(GravitySweep, TheResultsTableIsTheProcessingOfEveryCommittedDrop) {
  using namespace gravsweep::results;
  const auto dir = std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "data" / "gravity_sweep";
  std::ifstream in(dir / "results.csv");
  ASSERT_TRUE(in) << "no " << (dir / "results.csv");
  std::map<std::string, std::map<std::string, std::string>> table;  // by job id
  for (auto& row : csv_table_rows(in)) table[row.at("job_id")] = std::move(row);
  std::size_t trials = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (!std::filesystem::exists(entry.path() / "trials.csv")) continue;
    const std::string folder = entry.path().filename().string();
    Campaign c = load_campaign(entry.path().string());
    reprocess_campaign(c, {"froude", ""});
    ASSERT_TRUE(c.issues.empty()) << folder;
    for (const auto& t : c.trials) {
      ++trials;
      SCOPED_TRACE(folder + " " + t.info.trial_id);
      ASSERT_EQ(table.count(t.info.trial_id), 1u);
      const auto& row = table.at(t.info.trial_id);
      EXPECT_EQ(row.at("folder"), folder);
      const Metrics& m = t.processed.metrics;
      for (const auto& [column, value] :
           {std::pair{"zstop_m", m.zstop_m}, std::pair{"tstop_s", m.tstop_s}, std::pair{"apeak_m_s2", m.apeak_m_s2},
            std::pair{"vc_m_s", m.vc_m_s}, std::pair{"zstop_surface_m", m.zstop_surface_m},
            std::pair{"cutoff_hz", m.cutoff_hz}, std::pair{"end_hold_s", m.end_hold_s}})
        EXPECT_NEAR(std::stod(row.at(column)), value, 1e-6 * std::abs(value) + 1e-12) << column;
    }
  }
  EXPECT_EQ(trials, table.size()) << "a row of results.csv in no committed folder";
}

// `model fit --per-froude` gives the held-out errors by gravity level and Froude number, which the
// medians hide: without the linear drag 23 of the 25 cells are beyond a target and Fr 0.2 is
// 31-34 % shallow at 9.81 and 0.001 m/s2; with it 15, none beyond 15 % in zstop. And `--weight
// mg` (residuals in units of m g) moves the constants and predicts worse than each drop's own
// force units (GRAVITY.md, "And on the weighting").
TEST(GravitySweep, ModelFitGivesTheCellsBeyondATargetAndTheWeightingSensitivity) {
  const std::string law = "scaled_base+gravity_depth_friction";
  const auto r = gravsweep::testing::run_gravsweep(
      "model fit" + sweep_levels() + " --model " + law + "+viscous_drag:g^0.5 --baseline " + law + " --format json",
      false);
  ASSERT_EQ(r.code, 0) << r.out;
  const auto doc = nlohmann::json::parse(r.out);
  std::map<std::string, int> beyond, cells;
  std::map<std::string, double> worst;
  for (const auto& cell : doc.at("by_froude")) {
    const std::string model = cell.at("model");
    ++cells[model];
    beyond[model] += cell.at("beyond_target") == "yes";
    const double z = cell.at("zstop_mean_err_pct").get<double>();
    worst[model] = std::max(worst[model], std::abs(z));
  }
  EXPECT_EQ(cells[law], 25);
  EXPECT_EQ(beyond[law], 23);
  EXPECT_GT(worst[law], 30.0);
  EXPECT_EQ(beyond[law + "+viscous_drag:g^0.5"], 15);
  EXPECT_LT(worst[law + "+viscous_drag:g^0.5"], 15.0);

  std::string out;
  const auto own = csv_rows("model fit" + sweep_levels() + " --model " + law + " --no-plot", out);
  const auto mg = csv_rows("model fit" + sweep_levels() + " --model " + law + " --weight mg --no-plot", out);
  const auto value = [](const std::vector<std::map<std::string, std::string>>& rows,
                        const std::string& name) -> double {
    for (const auto& row : rows)
      if (row.at("parameter") == name) return std::stod(row.at("value"));
    ADD_FAILURE() << "no " << name;
    return NAN;
  };
  EXPECT_NEAR(value(own, "scaled_base.phi"), 0.866, 0.01);
  EXPECT_NEAR(value(mg, "scaled_base.phi"), 1.127, 0.01);
  EXPECT_NEAR(value(mg, "gravity_depth_friction.kappa_kg_m"), 21.5, 0.2);
}

// The committed gravity sweep (data/gravity_sweep/, GRAVITY.md): the collapse, the leave-one-level-
// out law, the regime map and `model rank --scaled` on its five levels must keep giving the values
// GRAVITY.md states, so that a change to processing or fitting that moves them fails here.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "results/io/csv.h"
#include "results/measurements/campaign.h"
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
// traces. Two levels (9.81, 1.62 m/s2): the Froude-scaled duration falls on one curve (ratio 1.03),
// the scaled depth lies 5-10 % lower at 1.62 m/s2 below Fr 1 (ratio 1.39). All five levels (50
// drops, four decades of g): the depth collapses (ratio 1.00, the levels 4.9 % apart at equal Fr),
// the duration less well (1.55: the levels 17.7 % apart against 12.2 % within).
TEST(GravitySweep, TheCommittedLevelsCollapseInDepthAndLessInDuration) {
  const auto collapse = [](const std::string& folders, const char* trials) {
    const auto r = gravsweep::testing::run_gravsweep("model collapse" + folders + " --format csv", false);
    EXPECT_EQ(r.code, 0) << r.out;
    std::map<std::string, std::vector<std::string>> rows;
    std::istringstream in(r.out);
    gravsweep::results::CsvReader csv(in);
    std::vector<std::string> cells;
    int line = 0;
    while (csv.next(cells, line))
      if (cells.size() == 7) rows[cells[0]] = cells;
    EXPECT_EQ(rows.count("zstop_over_D"), 1u) << r.out;
    EXPECT_EQ(rows.count("tstop_sqrt_g_over_D"), 1u) << r.out;
    EXPECT_EQ(rows["zstop_over_D"][2], trials);
    return rows;
  };
  auto two = collapse(level_folder("g9.81") + level_folder("g1.62"), "14");
  EXPECT_NEAR(std::stod(two["tstop_sqrt_g_over_D"].at(6)), 1.03, 0.05);
  EXPECT_NEAR(std::stod(two["zstop_over_D"].at(6)), 1.39, 0.05);
  EXPECT_LT(std::stod(two["zstop_over_D"].at(5)), 15.0);  // the levels lie within 15 % at equal Fr
  auto five = collapse(sweep_levels(), "50");
  EXPECT_EQ(five["zstop_over_D"].at(1), "5");
  EXPECT_NEAR(std::stod(five["zstop_over_D"].at(6)), 1.00, 0.05);
  EXPECT_NEAR(std::stod(five["zstop_over_D"].at(5)), 4.9, 0.5);
  EXPECT_NEAR(std::stod(five["tstop_sqrt_g_over_D"].at(6)), 1.55, 0.05);
}

// Leave one level out on the five committed levels (GRAVITY.md, "One gravity-scaled law"): phi m g
// + kappa g z + m v^2/d1 fitted on four levels predicts the fifth within the targets (zstop
// 10 %, tstop 15 %) at 1.62 and 0.1 m/s2 and misses zstop at 0.01 m/s2 by 13 %, the verdict naming
// both regimes; the numbers are the ones GRAVITY.md states (within 1 point). Without the depth
// term (phi m g + m v^2/d1) every level is missed by more than 30 % in zstop.
TEST(GravitySweep, OneDepthFrictionLawPredictsEachHeldOutLevelFromTheOtherFour) {
  std::string out;
  const auto rows = csv_rows("model lolo" + sweep_levels() + " --law scaled_base+gravity_depth_friction", out);
  std::printf("%s", out.c_str());
  ASSERT_EQ(rows.size(), 5u) << out;
  const std::map<std::string, std::pair<double, double>> stated{
      {"9.81", {6.5, 3.2}}, {"1.62", {4.6, 6.0}}, {"0.1", {6.5, 5.6}}, {"0.01", {13.0, 5.8}}, {"0.001", {12.4, 25.9}}};
  for (const auto& r : rows) {
    const std::string g = r.at("held_out_g_m_s2");
    SCOPED_TRACE(g);
    ASSERT_EQ(stated.count(g), 1u);
    EXPECT_NEAR(std::stod(r.at("zstop_median_err_pct")), stated.at(g).first, 1.0);
    EXPECT_NEAR(std::stod(r.at("tstop_median_err_pct")), stated.at(g).second, 1.0);
    const bool outer = g == "9.81" || g == "0.001";
    EXPECT_EQ(r.at("range"), outer ? "outside" : "inside");
    if (g == "1.62" || g == "0.1") EXPECT_EQ(r.at("verdict").rfind("within the targets", 0), 0u) << r.at("verdict");
    if (g == "0.01") {
      EXPECT_EQ(r.at("verdict").rfind("misses the targets: zstop", 0), 0u) << r.at("verdict");
      EXPECT_NE(r.at("verdict").find("both regimes miss"), std::string::npos) << r.at("verdict");
    }
  }
  const auto plain = csv_rows("model lolo" + sweep_levels(), out);
  ASSERT_EQ(plain.size(), 5u) << out;
  for (const auto& r : plain) EXPECT_GT(std::stod(r.at("zstop_median_err_pct")), 30.0) << r.at("held_out_g_m_s2");
}

// The regime map of the depth-friction law fitted on all five levels: one crossover at the surface
// for every level, Fr 0.51 (GRAVITY.md), a third of paper II's 1.5; a drop that starts above it
// crosses it on its way down, one that starts below is quasi-static from the impact on.
TEST(GravitySweep, TheRegimeMapOfTheFiveLevelsCrossesAtFroude051) {
  std::string out;
  const auto rows = csv_rows("model regimes" + sweep_levels() + " --law scaled_base+gravity_depth_friction", out);
  std::printf("%s", out.c_str());
  ASSERT_EQ(rows.size(), 50u) << out;
  for (const auto& r : rows) {
    SCOPED_TRACE(r.at("trial_id"));
    const double crossover = std::stod(r.at("law_crossover_fr"));
    EXPECT_NEAR(crossover, 0.511, 0.005);
    EXPECT_EQ(r.at("paper_ii_fr"), "1.5");
    EXPECT_EQ(r.at("crossover_fr") != "-", std::stod(r.at("impact_fr")) > crossover) << r.at("impact_fr");
  }
}

// `model rank --scaled` on the five levels names the depth friction that follows g, and reports
// the best generated form (a drag concentrated within two grain diameters of the surface) as
// tried but not named: it fits the traces better held out but lengthens the predicted durations.
TEST(GravitySweep, TheScaledRankOnTheFiveLevelsNamesTheDepthFrictionThatFollowsGravity) {
  const auto r = gravsweep::testing::run_gravsweep("model rank" + sweep_levels() + " --scaled", false);
  ASSERT_EQ(r.code, 0) << r.out;
  std::printf("%s", r.out.c_str());
  EXPECT_NE(r.out.find("Verdict: missing effect: gravity_depth_friction ("), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("the best generated form, c * v^2*exp(-z/0.02):shared"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(": not named"), std::string::npos) << r.out;
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
}

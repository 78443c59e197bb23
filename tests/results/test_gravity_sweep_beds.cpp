// The gravity sweep beyond its five ramped 21 cm beds (GRAVITY.md): beds poured at their gravity, a
// second bed, the deeper and wider bed at 0.01 m/s2, and the law with the Froude-scaled linear drag
// on them, each against the values GRAVITY.md states.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "gravity_sweep_helpers.h"
#include "tests/common/temp_dir.h"

using namespace gravsweep::testing::sweep;
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

  // The linear drag counts as drag: every crossover moves down, and paper II's ~1.5 stays between
  // the two whole-collision definitions.
  const auto regimes = gravsweep::testing::run_gravsweep("model regimes" + sweep_levels() + " --law " + drag, false);
  EXPECT_NE(regimes.out.find("Fr 0.345 +- 0.025 by the law at the surface"), std::string::npos) << regimes.out;
  EXPECT_NE(
      regimes.out.find("the drag does half the work at Fr 0.855 +- 0.043 and carries half the impulse at Fr 1.77"),
      std::string::npos)
      << regimes.out;
}

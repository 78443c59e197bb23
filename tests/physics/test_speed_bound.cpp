// The speed bounds of the adaptive step (engine/scenario/time_step.h): System::max_approach_speed_m_s
// takes the relative normal speed of the pairs that can touch within an interval, where twice the
// fastest particle's speed bounds any pair's relative speed. Beads of Table 1 (radius 5 mm, skin
// 1 mm), no gravity, one thread.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "engine/core/error.h"
#include "engine/scenario/time_step.h"
#include "physics_helpers.h"

namespace gravsweep {
namespace {

using test::bead_mass_kg;
using test::kBeadRadius_m;
using test::two_material_config;

constexpr double kSpeed_m_s = 0.01;
constexpr double kShortInterval_s = 1e-4;  ///< 2 x 5 v x interval = 10 um, far below half the skin

/// Grain 0 at the origin; grain 1 0.5 mm beyond contact along x (listed: the skin is 1 mm);
/// grain 2 far from both. Each velocity as given. One step with no force between them builds the
/// list (their speeds move them by nanometres).
struct ThreeGrains {
  System sys{two_material_config("hertz", 0.9, 0.5)};
  ThreeGrains(const Vec3& v0, const Vec3& v1, const Vec3& v2, double gap_m = 5e-4) {
    const double m = bead_mass_kg();
    sys.particles.add(Vec3::Zero(), kBeadRadius_m, m, 0, SizeClass::grain);
    sys.particles.add(Vec3(2 * kBeadRadius_m + gap_m, 0, 0), kBeadRadius_m, m, 0, SizeClass::grain);
    sys.particles.add(Vec3(0, 0.1, 0), kBeadRadius_m, m, 0, SizeClass::grain);
    sys.particles.velocity_m_s = {v0, v1, v2};
    sys.mutable_config().dt_s = 1e-7;
    sys.step();
  }
};

TEST(SpeedBound, ApproachingGrainsGiveTheirSpeedAlongTheNormalNotTheFastestGrainsTwice) {
  // Grain 1 approaches grain 0 at v along the line of centres; grain 2, alone, moves at 5 v.
  ThreeGrains g(Vec3::Zero(), Vec3(-kSpeed_m_s, 0, 0), Vec3(5 * kSpeed_m_s, 0, 0));
  EXPECT_NEAR(g.sys.max_approach_speed_m_s(kShortInterval_s), kSpeed_m_s, 1e-12);
  EXPECT_NEAR(2 * g.sys.max_particle_speed_m_s(), 10 * kSpeed_m_s, 1e-12);
}

TEST(SpeedBound, AGrainSlidingPastItsNeighbourOrMovingAwayDoesNotCount) {
  ThreeGrains sliding(Vec3::Zero(), Vec3(0, 3 * kSpeed_m_s, 0), Vec3::Zero());
  EXPECT_LT(sliding.sys.max_approach_speed_m_s(kShortInterval_s), 1e-6 * kSpeed_m_s);
  ThreeGrains leaving(Vec3::Zero(), Vec3(kSpeed_m_s, 0, 0), Vec3::Zero());
  EXPECT_EQ(leaving.sys.max_approach_speed_m_s(kShortInterval_s), 0.0);
}

TEST(SpeedBound, ATouchingPairCountsWhetherItApproachesOrSeparates) {
  // 1 um of overlap: the pair touches and separates at about v (its contact pushes it apart).
  ThreeGrains g(Vec3::Zero(), Vec3(kSpeed_m_s, 0, 0), Vec3::Zero(), -1e-6);
  const auto& p = g.sys.particles;
  const Vec3 n = (p.position_m[1] - p.position_m[0]).normalized();
  const double separating_m_s = (p.velocity_m_s[1] - p.velocity_m_s[0]).dot(n);
  ASSERT_GT(separating_m_s, 0.9 * kSpeed_m_s);
  EXPECT_NEAR(g.sys.max_approach_speed_m_s(kShortInterval_s), separating_m_s, 1e-12);
}

TEST(SpeedBound, AGrainWithinReachOfAWallCountsWithItsWholeSpeed) {
  ThreeGrains g(Vec3::Zero(), Vec3::Zero(), Vec3::Zero());
  g.sys.walls.push_back(Wall::plane("floor", Vec3(0, 0, -kBeadRadius_m - 2e-4), Vec3::UnitZ(), 1));
  g.sys.invalidate();
  g.sys.particles.velocity_m_s[0] = Vec3(0, 2 * kSpeed_m_s, 0);  // sideways: still counted
  g.sys.step();
  EXPECT_NEAR(g.sys.max_approach_speed_m_s(kShortInterval_s), 2 * kSpeed_m_s, 1e-9);
}

TEST(SpeedBound, WhereTheListCouldBeRebuiltWithinTheIntervalItIsTwiceTheFastestSpeed) {
  // Before the first step no list is built.
  System fresh(two_material_config("hertz", 0.9, 0.5));
  fresh.particles.add(Vec3::Zero(), kBeadRadius_m, bead_mass_kg(), 0, SizeClass::grain);
  fresh.particles.velocity_m_s[0] = Vec3(kSpeed_m_s, 0, 0);
  EXPECT_EQ(fresh.max_approach_speed_m_s(kShortInterval_s), 2 * kSpeed_m_s);
  // Grain 2 could cover half the skin (0.5 mm) within 10 ms at 5 v (2 x 0.05 m/s x 10 ms = 1 mm):
  // a pair not listed now could touch, so no listed pair bounds it.
  ThreeGrains g(Vec3::Zero(), Vec3(-kSpeed_m_s, 0, 0), Vec3(5 * kSpeed_m_s, 0, 0));
  EXPECT_EQ(g.sys.max_approach_speed_m_s(1e-2), 2 * g.sys.max_particle_speed_m_s());
}

// A lattice of 400 grains (some touching) with random speeds over three decades: the bound is the
// largest normal speed over every listed pair and wall candidate, computed here pair by pair, on 1
// and 2 threads alike.
TEST(SpeedBound, TheBoundIsTheMaximumOverEveryListedPairOnAnyThreadCount) {
  for (int threads : {1, 2}) {
    auto cfg = two_material_config("hertz", 0.9, 0.5);
    cfg.threads = threads;
    cfg.parallel_min_particles = 1;
    System sys(cfg);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(0, 1);
    const double m = bead_mass_kg(), pitch_m = 2 * kBeadRadius_m + 2e-4;
    for (int a = 0; a < 8; ++a)
      for (int b = 0; b < 10; ++b)
        for (int c = 0; c < 5; ++c) {
          const Vec3 jitter(unit(rng), unit(rng), unit(rng));
          sys.particles.add(Vec3(a, b, c) * pitch_m + 3e-4 * jitter, kBeadRadius_m, m, 0, SizeClass::grain);
          const Vec3 dir = Vec3(unit(rng), unit(rng), unit(rng)) - Vec3::Constant(0.5);
          sys.particles.velocity_m_s.back() = 1e-3 * std::pow(1e3, unit(rng)) * dir.normalized() * 1e-3;
        }
    sys.walls.push_back(Wall::plane("floor", Vec3(0, 0, -kBeadRadius_m - 1e-4), Vec3::UnitZ(), 1));
    sys.mutable_config().dt_s = 1e-7;
    sys.step();
    const auto& p = sys.particles;
    const auto& list = sys.neighbor_list();
    double expected = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      for (std::uint32_t k = list.offset[i]; k < list.offset[i + 1]; ++k) {
        const std::uint32_t j = list.neighbor[k];
        const Vec3 d = p.position_m[j] - p.position_m[i];
        const double closing = -(p.velocity_m_s[j] - p.velocity_m_s[i]).dot(d) / d.norm();
        expected = std::max(expected, d.norm() < p.radius_m[i] + p.radius_m[j] ? std::abs(closing) : closing);
      }
      if (p.position_m[i].z() < kBeadRadius_m) expected = std::max(expected, p.velocity_m_s[i].norm());  // floor row
    }
    ASSERT_GT(list.pairs(), 900u);
    EXPECT_EQ(sys.max_approach_speed_m_s(kShortInterval_s), expected) << threads << " threads";
  }
}

TEST(SpeedBound, TheNormalApproachRuleTakesLongerStepsThanTheFastestParticleRule) {
  ThreeGrains g(Vec3::Zero(), Vec3(-kSpeed_m_s, 0, 0), Vec3(5 * kSpeed_m_s, 0, 0));
  AdaptiveStep fastest{20, 1e-3};
  AdaptiveStep approach = fastest;
  approach.speed_bound = AdaptiveStep::SpeedBound::normal_approach;
  const double fixed_dt_s = 1e-7;
  const double interval_s = 2e-3;  // 2 x 5 v x 2 ms = 0.2 mm, below half the skin
  const long long n_fastest = choose_step(g.sys, fastest, fixed_dt_s, interval_s);
  const long long n_approach = choose_step(g.sys, approach, fixed_dt_s, interval_s);
  // t_H ~ v^(-1/5): 10 times slower gives a 10^(1/5) = 1.58 times longer step.
  EXPECT_NEAR(static_cast<double>(n_fastest) / static_cast<double>(n_approach), 1.585, 0.1);
  EXPECT_EQ(speed_bound_named("normal_approach"), AdaptiveStep::SpeedBound::normal_approach);
  EXPECT_EQ(speed_bound_named("fastest_particle"), AdaptiveStep::SpeedBound::fastest_particle);
  EXPECT_THROW((void)speed_bound_named("fastest"), ConfigError);
}

}  // namespace
}  // namespace gravsweep

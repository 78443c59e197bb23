// Memory layout of the contact histories: the per-pair ContactHistory (48 bytes), the
// FrameHistory kept only for hooke / zhang, and the sparse wall histories stored beside the wall
// candidates. Each test compares a run with a reference run that must give bit-identical states;
// a history lost, reset or attached to the wrong pair at a rebuild, a renumbering or a switch of
// storage changes the trajectories.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <tuple>

#include "physics_helpers.h"

using namespace gravsweep;
using namespace gravsweep::test;

namespace {

constexpr double kLatticeSpacingFactor = 2.0;  ///< grain spacing / radius: touching, no force
constexpr int kSteps = 1500;

/// Grains in a 4 x 3 x 2 lattice resting against a floor and a side wall, under gravity tilted
/// towards the side wall, with random spins: sliding, rolling and twisting contacts with grains and
/// both walls from the first step. With `far_grain` an extra grain far from everything comes first
/// (index 0), so removing it renumbers every other grain.
SystemConfig layout_config(const std::string& law, const std::string& rolling) {
  SystemConfig c = two_material_config(law, 0.7, 0.3, rolling);
  for (auto& m : c.materials) {
    m.mu_rolling = 0.05;
    m.mu_twisting = 0.05;
  }
  c.gravity_m_s2 = Vec3(-3.0, 0.5, -9.81);
  return c;
}

void fill(System& s, bool far_grain) {
  const double r = kBeadRadius_m, m = bead_mass_kg();
  s.walls.push_back(Wall::plane("floor", Vec3::Zero(), Vec3::UnitZ(), 1));
  s.walls.push_back(Wall::plane("side", Vec3::Zero(), Vec3::UnitX(), 1));
  if (far_grain) s.particles.add(Vec3(0.3, 0.3, 0.3), r, m, 0, SizeClass::grain);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double a = kLatticeSpacingFactor * r;
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 4; ++x) {
        const ParticleIndex i = s.particles.add(Vec3(r + x * a, y * a, r + z * a), r, m, 0, SizeClass::grain);
        const Vec3 v = Vec3(u(rng), u(rng), 0.0) * 1e-3;
        s.particles.set_velocity(i, v, Vec3(u(rng), u(rng), u(rng)) * 5.0);
      }
}

void expect_same_grains(const System& a, std::size_t a_first, const System& b, std::size_t b_first) {
  ASSERT_EQ(a.particles.size() - a_first, b.particles.size() - b_first);
  for (std::size_t k = 0; k + a_first < a.particles.size(); ++k) {
    EXPECT_EQ(a.particles.position_m[a_first + k], b.particles.position_m[b_first + k]) << "grain " << k;
    EXPECT_EQ(a.particles.omega_rad_s[a_first + k], b.particles.omega_rad_s[b_first + k]) << "grain " << k;
  }
}

class HistoryLayoutTest : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

}  // namespace

// Rebuilding the neighbour list and the wall candidates every step (mutable_config() forces
// initialize(), which rebuilds both) carries every pair's and every wall contact's history over.
TEST_P(HistoryLayoutTest, RebuildEveryStepChangesNothing) {
  const auto& [law, rolling] = GetParam();
  System ref(layout_config(law, rolling)), rebuilt(layout_config(law, rolling));
  fill(ref, false);
  fill(rebuilt, false);
  long long wall_contacts = 0;
  for (int s = 0; s < kSteps; ++s) {
    ref.step();
    rebuilt.mutable_config();
    rebuilt.step();
    wall_contacts += ref.stats().wall_contacts;
  }
  EXPECT_GT(wall_contacts, 10LL * kSteps);  // both walls touched throughout (18 grains at rest)
  EXPECT_GT(ref.stats().contacts, 10);
  EXPECT_NO_FATAL_FAILURE(expect_same_grains(ref, 0, rebuilt, 0));
}

// Removing a grain renumbers the others; their pair and wall histories follow them (compared
// with a run that never had the grain).
TEST_P(HistoryLayoutTest, RemovingAGrainKeepsEveryOtherHistory) {
  const auto& [law, rolling] = GetParam();
  System ref(layout_config(law, rolling)), removed(layout_config(law, rolling));
  fill(ref, false);
  fill(removed, true);
  for (int s = 0; s < kSteps; ++s) {
    if (s == kSteps / 2) {
      std::vector<bool> drop(removed.particles.size(), false);
      drop[0] = true;
      removed.remove_particles(drop);
    }
    ref.step();
    removed.step();
  }
  EXPECT_NO_FATAL_FAILURE(expect_same_grains(ref, 0, removed, 0));
}

// The pair loop's two ways (a branch per listed pair, or the branch-free filter into a buffer of
// touching pairs, chosen by SystemConfig::pair_filter_min_pairs) give bit-identical trajectories,
// with both walls, rolling, twisting and contacts that open and close; on 1 and 2 threads.
TEST(PairFilter, BothWaysGiveTheSameTrajectories) {
  for (int threads : {1, 2}) {
    SystemConfig branch = layout_config("hertz", "sunday"), filter = branch;
    branch.pair_filter_min_pairs = UINT32_MAX;
    filter.pair_filter_min_pairs = 0;
    branch.threads = filter.threads = threads;
    branch.parallel_min_particles = filter.parallel_min_particles = 1;
    System a(branch), b(filter);
    fill(a, true);
    fill(b, true);
    long long contacts = 0;
    for (int s = 0; s < kSteps; ++s) {
      a.step();
      b.step();
      contacts += a.stats().contacts;
      ASSERT_EQ(a.stats().contacts, b.stats().contacts) << "step " << s << ", " << threads << " threads";
    }
    EXPECT_GT(contacts, 10LL * kSteps);
    EXPECT_NO_FATAL_FAILURE(expect_same_grains(a, 0, b, 0));
    for (std::size_t i = 0; i < a.particles.size(); ++i)
      EXPECT_EQ(a.particles.velocity_m_s[i], b.particles.velocity_m_s[i]) << "particle " << i;
  }
}

// A pair of two fixed particles is dropped from the batch of touching pairs, and the pairs after
// it in the same batch keep their own lanes: the lattice's grains, a fixed pair (overlapping) and
// a free grain resting on one of the two fixed ones move bit for bit as when the fixed particles
// lie apart (their pair not listed), with the same contact counts; both pair-filter ways, 1 and 2
// threads.
TEST(PairFilter, AFixedPairLeavesTheBatchAndThePairsAfterItKeepTheirLanes) {
  const double r = kBeadRadius_m, m = bead_mass_kg();
  auto build = [&](System& s, bool fixed_pair_touches) {
    fill(s, false);
    const Vec3 base(0.3, 0.3, 0.05);
    const Vec3 other = fixed_pair_touches ? base + Vec3(1.6 * r, 0, 0) : base + Vec3(0, 0.2, 0);
    s.particles.add(other, r, m, 0, SizeClass::grain, true);
    s.particles.add(base, r, m, 0, SizeClass::grain, true);
    s.particles.add(base + Vec3(0, 0, 1.98 * r), r, m, 0, SizeClass::grain);
  };
  for (int threads : {1, 2})
    for (std::uint32_t min_pairs : {0u, UINT32_MAX}) {
      SystemConfig c = layout_config("hertz", "sunday");
      c.pair_filter_min_pairs = min_pairs;
      c.threads = threads;
      c.parallel_min_particles = 1;
      System a(c), b(c);
      build(a, true);
      build(b, false);
      const std::size_t moved = a.particles.size() - 3, resting = a.particles.size() - 1;
      for (int s = 0; s < kSteps; ++s) {
        a.step();
        b.step();
        ASSERT_EQ(a.stats().contacts, b.stats().contacts) << "step " << s << ", " << threads << " threads";
        if (s == 0) ASSERT_GE(a.contact_counts()[resting], 1) << "the free grain touches a fixed one";
      }
      for (std::size_t k = 0; k < a.particles.size(); ++k) {
        if (k == moved) continue;  // the fixed particle placed apart in b
        EXPECT_EQ(a.particles.position_m[k], b.particles.position_m[k]) << "particle " << k;
        EXPECT_EQ(a.particles.omega_rad_s[k], b.particles.omega_rad_s[k]) << "particle " << k;
      }
    }
}

// contact_count(i) (the projectile's contacts in every trace sample) counts the pairs listed under
// i and under its partners' rows, and i's walls: after a force pass it equals contact_counts() and
// the spheres and walls that overlap i at the positions of that pass.
TEST(ContactCount, CountsEveryTouchingPartnerAndWall) {
  System s(layout_config("hertz", "sunday"));
  fill(s, true);
  for (int k = 0; k < kSteps / 3; ++k) s.step();
  s.compute_forces();  // active histories now match the current positions
  const auto& p = s.particles;
  const std::vector<int> all = s.contact_counts();
  int touching_grains = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    int expected = 0;
    for (std::size_t j = 0; j < p.size(); ++j)
      if (j != i && (p.position_m[j] - p.position_m[i]).norm() < p.radius_m[i] + p.radius_m[j]) ++expected;
    for (const Wall& w : s.walls) {
      WallTouch touch;
      if (touch_wall(w, p.position_m[i], p.radius_m[i], touch)) ++expected;
    }
    EXPECT_EQ(s.contact_count(static_cast<ParticleIndex>(i)), expected) << "particle " << i;
    EXPECT_EQ(all[i], expected) << "particle " << i;
    touching_grains += expected > 0;
  }
  EXPECT_GT(touching_grains, 20);  // every lattice grain touches something; grain 0 nothing
  EXPECT_EQ(all[0], 0);
}

INSTANTIATE_TEST_SUITE_P(Laws, HistoryLayoutTest,
                         ::testing::Values(std::make_tuple("hertz", "sunday"), std::make_tuple("hertz", "zhang"),
                                           std::make_tuple("hooke", "zhang"), std::make_tuple("hooke", "none")));

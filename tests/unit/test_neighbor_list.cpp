// Neighbour list: finds exactly the pairs a brute-force search finds, for a 10:1 size ratio and
// polydisperse grains, and keeps contact histories across rebuilds.
#include <gtest/gtest.h>

#include <random>
#include <map>
#include <set>

#include "engine/neighbor/verlet_list.h"

using namespace gravsweep;

namespace {
Particles random_particles(int n, std::uint64_t seed) {
  Particles p;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 0.1), r(0.004, 0.006);
  p.add(Vec3(0.05, 0.05, 0.05), 0.05, 1.0, 2, SizeClass::projectile);  // 10 cm projectile
  for (int i = 0; i < n; ++i) p.add(Vec3(u(rng), u(rng), u(rng)), r(rng), 1e-3, 0, SizeClass::grain);
  p.add(Vec3(0.09, 0.01, 0.02), 0.03, 0.5, 2, SizeClass::projectile);
  return p;
}
std::set<std::pair<std::uint32_t, std::uint32_t>> listed(const VerletList& l) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> s;
  for (std::size_t i = 0; i + 1 < l.offset.size(); ++i)
    for (auto k = l.offset[i]; k < l.offset[i + 1]; ++k) s.insert({static_cast<std::uint32_t>(i), l.neighbor[k]});
  return s;
}
}  // namespace

TEST(VerletList, MatchesBruteForceWithLargeParticles) {
  Particles p = random_particles(600, 7);
  const double skin = 0.001;
  VerletList l;
  l.build(p, skin, 2);
  std::set<std::pair<std::uint32_t, std::uint32_t>> expect;
  for (std::uint32_t i = 0; i < p.size(); ++i)
    for (std::uint32_t j = i + 1; j < p.size(); ++j) {
      const double cut = p.radius_m[i] + p.radius_m[j] + skin;
      if ((p.position_m[i] - p.position_m[j]).squaredNorm() < cut * cut) expect.insert({i, j});
    }
  EXPECT_EQ(listed(l), expect);
  EXPECT_GT(expect.size(), 100u);
}

TEST(VerletList, HistorySurvivesRebuild) {
  Particles p = random_particles(200, 3);
  VerletList l;
  l.build(p, 0.001, 1);
  ASSERT_GT(l.pairs(), 0u);
  for (std::size_t k = 0; k < l.history.size(); ++k) {
    l.history[k].active = true;
    l.history[k].duration_s = static_cast<double>(k);
  }
  const auto before = listed(l);
  std::map<std::pair<std::uint32_t, std::uint32_t>, double> dur;
  for (std::size_t i = 0; i + 1 < l.offset.size(); ++i)
    for (auto k = l.offset[i]; k < l.offset[i + 1]; ++k)
      dur[{static_cast<std::uint32_t>(i), l.neighbor[k]}] = l.history[k].duration_s;
  p.position_m[5] += Vec3(0.01, 0, 0);  // move one grain: some pairs change
  EXPECT_TRUE(l.needs_rebuild(p));
  l.build(p, 0.001, 2);
  int kept = 0;
  for (std::size_t i = 0; i + 1 < l.offset.size(); ++i)
    for (auto k = l.offset[i]; k < l.offset[i + 1]; ++k) {
      auto it = dur.find({static_cast<std::uint32_t>(i), l.neighbor[k]});
      if (it != dur.end()) {
        EXPECT_TRUE(l.history[k].active);
        EXPECT_EQ(l.history[k].duration_s, it->second);
        ++kept;
      } else {
        EXPECT_FALSE(l.history[k].active);
      }
    }
  EXPECT_GT(kept, 0);
}

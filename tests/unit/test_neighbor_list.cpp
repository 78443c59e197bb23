// Neighbour list: finds exactly the pairs a brute-force search finds, for a 10:1 size ratio and
// polydisperse grains, and keeps contact histories across rebuilds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>
#include <map>
#include <set>

#include "engine/neighbor/verlet_list.h"
#include "engine/system/force_loop.h"

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

// The build writes rows in chunks of 256, each chunk to its own buffer (verlet_list.cpp): several
// chunks, both thread counts, large particles first and last; every row sorted by neighbour (the
// history merge of the next build relies on it).
TEST(VerletList, MatchesBruteForceWithLargeParticles) {
  for (const int grains : {600, 1500})
    for (const int threads : {1, 2}) {
      Particles p = random_particles(grains, 7);
      const double skin = 0.001;
      VerletList l;
      l.build(p, skin, threads);
      std::set<std::pair<std::uint32_t, std::uint32_t>> expect;
      for (std::uint32_t i = 0; i < p.size(); ++i)
        for (std::uint32_t j = i + 1; j < p.size(); ++j) {
          const double cut = p.radius_m[i] + p.radius_m[j] + skin;
          if ((p.position_m[i] - p.position_m[j]).squaredNorm() < cut * cut) expect.insert({i, j});
        }
      EXPECT_EQ(listed(l), expect) << grains << " grains, " << threads << " threads";
      EXPECT_EQ(l.pairs(), expect.size());
      EXPECT_GT(expect.size(), 100u);
      for (std::size_t i = 0; i + 1 < l.offset.size(); ++i)
        EXPECT_TRUE(std::is_sorted(l.neighbor.begin() + l.offset[i], l.neighbor.begin() + l.offset[i + 1])) << i;
    }
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

// The rows of the pair loop are split between threads by work, not by count. The work
// prefix of a build weighs a touching pair (an active history) kTouchingWork more than a listed
// one, plus kRowWork per row, and goes when the rows change (extend, remap, clear).
TEST(VerletList, WorkPrefixWeighsTouchingPairsAndGoesWhenTheRowsChange) {
  Particles p = random_particles(200, 3);
  VerletList l;
  l.build(p, 0.001, 1);
  ASSERT_EQ(l.work_offset.size(), p.size() + 1);
  EXPECT_EQ(l.work_offset.back(), l.pairs() + kRowWork * p.size());  // no history active yet
  std::size_t active = 0;
  for (std::size_t k = 0; k < l.history.size(); k += 2, ++active) l.history[k].active = true;
  l.build(p, 0.001, 2);  // same positions: same pairs, histories carried over
  ASSERT_EQ(l.work_offset.size(), p.size() + 1);
  EXPECT_EQ(l.work_offset.back(), l.pairs() + kTouchingWork * active + kRowWork * p.size());
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_GE(l.work_offset[i + 1], l.work_offset[i] + kRowWork);
  p.add(Vec3(0.5, 0.5, 0.5), 0.005, 1e-3, 0, SizeClass::grain);
  l.extend(p.size());
  EXPECT_TRUE(l.work_offset.empty()) << "rows changed: the split falls back to listed pairs";
  l.build(p, 0.001, 1);
  EXPECT_EQ(l.work_offset.size(), p.size() + 1);
}

// The work model is the list's own (SystemConfig::pair_work, `gravsweep bench --pair-work`): other
// weights give the prefix those weights, and a wall candidate adds its weight to the rows from its
// particle's on.
TEST(VerletList, WorkPrefixTakesTheListsWeights) {
  Particles p = random_particles(200, 3);
  VerletList l;
  l.work = PairWork{5, 3, 7};
  l.build(p, 0.001, 1);
  std::size_t active = 0;
  for (std::size_t k = 0; k < l.history.size(); k += 2, ++active) l.history[k].active = true;
  l.build(p, 0.001, 1);
  ASSERT_EQ(l.work_offset.size(), p.size() + 1);
  EXPECT_EQ(l.work_offset.back(), l.pairs() + 3 * active + 5 * p.size());
  const std::uint32_t before_10 = l.work_offset[10], before_11 = l.work_offset[11], last = l.work_offset.back();
  const std::size_t walls = 2;
  l.add_wall_work({static_cast<std::uint32_t>(10 * walls), static_cast<std::uint32_t>(10 * walls + 1)}, walls);
  EXPECT_EQ(l.work_offset[10], before_10) << "rows before particle 10 keep their work";
  EXPECT_EQ(l.work_offset[11], before_11 + 2 * 7) << "particle 10's two wall candidates";
  EXPECT_EQ(l.work_offset.back(), last + 2 * 7);
}

TEST(BalancedRows, SplitsTheWorkNotTheRows) {
  // 100 rows: the first 50 heavy (10 each, the compressed bottom of a bed), the rest light (1).
  std::vector<std::uint32_t> work(101, 0);
  for (std::size_t i = 0; i < 100; ++i) work[i + 1] = work[i] + (i < 50 ? 10u : 1u);
  const auto [b0, e0] = balanced_rows(work.data(), 0, 100, 0, 2);
  const auto [b1, e1] = balanced_rows(work.data(), 0, 100, 1, 2);
  EXPECT_EQ(b0, 0u);
  EXPECT_EQ(e0, b1) << "contiguous";
  EXPECT_EQ(e1, 100u) << "every row";
  EXPECT_LT(e0, 50u) << "the heavy half is shared: thread 0 gets fewer rows";
  const double w0 = work[e0] - work[b0], w1 = work[e1] - work[b1];
  EXPECT_LE(std::abs(w0 - w1), 10.0) << "the shares differ by at most one row's work";
  // One thread takes all; no rows, nothing; a per-row cost on top of plain offsets counts too.
  EXPECT_EQ(balanced_rows(work.data(), 0, 100, 0, 1), (std::pair<std::size_t, std::size_t>{0, 100}));
  EXPECT_EQ(balanced_rows(work.data(), 0, 0, 1, 2), (std::pair<std::size_t, std::size_t>{0, 0}));
  std::vector<std::uint32_t> flat(101, 0);  // no pairs at all: the row cost alone splits in half
  EXPECT_EQ(balanced_rows(flat.data(), kRowWork, 100, 1, 2), (std::pair<std::size_t, std::size_t>{50, 100}));
}

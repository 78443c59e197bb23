// Half Verlet neighbour list with a skin, built from a cell list. Each unordered pair (i, j), i < j,
// appears once, under i, with its ContactHistory stored beside it; histories survive rebuilds.
//
// Large particles (radius above kLargeRadiusFactor x the smallest radius, e.g. the 10 cm projectile
// among 1 cm grains) are kept out of the cells; their pairs come from scanning the cells their
// bounding box covers, so the cell size stays set by the grains (correct for any size ratio and for
// polydisperse grains).
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "engine/contact/contact.h"
#include "engine/core/particles.h"

namespace gravsweep {

/// Work of a row of the pair loop, in units of a listed pair that does not touch (a distance
/// test): a row costs kRowWork, a touching pair kTouchingWork more (the contact law), a wall
/// candidate kWallWork. Touching 6 was set on the 0.1 m/s2 drop (perf per thread: 35.5 % /
/// 35.8 % of the samples at 6 and 9; 3 and 6 left thread 0 15 % more, 10 and 14 left thread 1
/// 10 % more); the wall weight 4 on the committed settled beds once the batched pair loop wrote
/// its lanes from the filter (`gravsweep bench --pair-work`: the paper bed's two threads 315 /
/// 318 us of loops a step at 4, 306 / 352 at 9; the sweep bed 746 / 743 at 4, 729 / 769 at 9;
/// the first 0.3 s of the 0.1 m/s2 drop the same at 4 and 9; BENCHMARKS.md).
inline constexpr std::uint32_t kRowWork = 2;
inline constexpr std::uint32_t kTouchingWork = 6;
/// Work of a particle-wall candidate in the same units (System adds it, add_wall_work).
inline constexpr std::uint32_t kWallWork = 4;

/// The work model the rows are split by (SystemConfig::pair_work; `gravsweep bench --pair-work`
/// measures others): a row, a touching pair beyond its distance test, a wall candidate.
struct PairWork {
  std::uint32_t row = kRowWork;
  std::uint32_t touching = kTouchingWork;
  std::uint32_t wall = kWallWork;
};

/// The listed pairs of one thread's share from which the pair loop (force_loop.h,
/// filter_listed_pairs) filters without a branch. Below it a branch per listed pair costs
/// less: the branch predictor of the machine of BENCHMARKS.md learns the repeating touch pattern
/// of ~15,000 pairs (the paper's 8,600-grain bed on 2 threads: 39.5 ns per particle-step with the
/// branch, 43.4 filtered) but not of ~33,000 (the 18,200-grain bed of the 0.1 m/s2 drop on 2
/// threads: 47.7 with the branch, 43.7 filtered; the paper's bed on 1 thread, 30,000 pairs: 83
/// and 78). Both ways visit the same pairs in the same order: forces and histories are
/// bit-identical (tests/physics/test_history_layout.cpp).
inline constexpr std::uint32_t kFilterMinPairs = 24000;

class VerletList {
 public:
  static constexpr double kLargeRadiusFactor = 2.5;

  /// Rebuilds the list for cutoff r_i + r_j + skin, carrying over histories of pairs still listed.
  void build(const Particles& p, double skin_m, int threads);

  /// True when some particle moved more than skin/2 since the last build (or nothing is built).
  [[nodiscard]] bool needs_rebuild(const Particles& p) const;
  /// The square of the largest displacement of a particle since the last build (m^2); infinite
  /// when nothing is built for these particles. needs_rebuild() is this beyond (skin/2)^2.
  [[nodiscard]] double max_displacement2_m2(const Particles& p) const;

  [[nodiscard]] std::size_t pairs() const { return neighbor.size(); }
  [[nodiscard]] long long builds() const { return builds_; }
  [[nodiscard]] double skin_m() const { return skin_m_; }
  [[nodiscard]] std::size_t bytes() const;
  /// Positions at the last build (for the displacement check), or null when nothing is built.
  [[nodiscard]] const Vec3* positions_at_build(std::size_t n) const {
    return position_at_build_.size() == n && offset.size() == n + 1 ? position_at_build_.data() : nullptr;
  }

  // CSR storage: pairs of particle i are [offset[i], offset[i+1]).
  std::vector<std::uint32_t> offset;
  std::vector<std::uint32_t> neighbor;
  std::vector<ContactHistory> history;
  /// Beside history, only when frame histories are kept (set_frame_history); else empty.
  std::vector<FrameHistory> frame_history;
  /// Pair-loop work before row i, for splitting the rows between threads (force_loop.h,
  /// balanced_rows): the sum over earlier rows of listed pairs + work.touching x touching pairs
  /// (active histories carried over at the build) + work.row. Set by build(); empty after
  /// clear(), extend() and remap() until the next build (the split then weighs listed pairs only).
  std::vector<std::uint32_t> work_offset;
  /// The weights of work_offset (System sets them from SystemConfig::pair_work).
  PairWork work;
  /// Adds work.wall per particle-wall candidate to the work prefix of the last build (codes
  /// particle * walls + wall, increasing, as System keeps them); nothing when there is none.
  void add_wall_work(const std::vector<std::uint32_t>& codes, std::size_t walls);

  /// Keep a FrameHistory per pair (the law or rolling model uses_frame_history). Switching it on
  /// gives every listed pair an empty record.
  void set_frame_history(bool keep);
  [[nodiscard]] bool keeps_frame_history() const { return keep_frame_; }

  /// The positions of the last build whatever their count (checkpoints, System::save_state).
  [[nodiscard]] const std::vector<Vec3>& build_positions() const { return position_at_build_; }
  /// Puts back what a checkpoint saved beside the public arrays (System::restore_state): the
  /// positions of the last build, its skin, the build count and whether frame histories are kept.
  void restore_build(std::vector<Vec3> position_at_build, double skin_m, long long builds, bool keep_frame) {
    position_at_build_ = std::move(position_at_build);
    skin_m_ = skin_m;
    builds_ = builds;
    keep_frame_ = keep_frame;
  }

  /// Forget everything (after particles were added: indices changed).
  void clear();

  /// Particles were appended (indices of the others unchanged): the new ones get empty rows, so
  /// the next build() carries every existing history over. Needs a build before use.
  void extend(std::size_t n_total);

  /// Drops the removed particles and renumbers the rest (order kept), keeping the histories of
  /// the surviving pairs. new_index[i] is the new index of particle i, or -1 if removed.
  void remap(const std::vector<long long>& new_index);

 private:
  std::vector<Vec3> position_at_build_;
  double skin_m_ = 0;
  bool keep_frame_ = false;
  long long builds_ = 0;
  /// The end of build(): the new rows replace the old, each listed pair keeping the histories it
  /// had; then the work prefix (work_offset).
  void carry_histories(std::vector<std::uint32_t> new_offset, std::vector<std::uint32_t> new_neighbor, int threads);
};

}  // namespace gravsweep

// How force_loop (force_loop.h) cuts the half neighbour list among its threads: each thread takes
// a run of rows holding an even share of the pair-loop work (VerletList::work_offset), so a thread
// whose rows hold more contacts gets fewer rows.
#pragma once
#include <cstddef>
#include <cstdint>
#include <utility>

#include "engine/neighbor/verlet_list.h"

namespace gravsweep {

/// The first row of thread k's share (of nt; k = nt gives n) of the half list: where the
/// pair-loop work before a row (`work`, n + 1 prefix sums, plus `row_work` per row) reaches k / nt
/// of the total, so a thread whose rows hold more touching pairs gets fewer rows. Static rows gave
/// thread 0 1.5x thread 1's pair work in a 0.1 m/s2 drop: after the gravity ramp the bottom of the
/// bed keeps its contacts and the top opens (BENCHMARKS.md). Depends only on the list:
/// every step between two builds cuts alike.
inline std::size_t balanced_cut(const std::uint32_t* work, std::uint32_t row_work, std::size_t n, int k, int nt) {
  if (n == 0 || k <= 0) return 0;
  if (k >= nt) return n;
  auto before = [&](std::size_t i) {
    return static_cast<double>(work[i]) + static_cast<double>(row_work) * static_cast<double>(i);
  };
  const double target = before(n) * k / nt;
  std::size_t lo = 0, hi = n;  // the first row with at least `target` work before it
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (before(mid) < target)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

/// Rows [begin, end) of thread t's share of nt: the cuts of balanced_cut at t and t + 1.
inline std::pair<std::size_t, std::size_t> balanced_rows(const std::uint32_t* work, std::uint32_t row_work,
                                                         std::size_t n, int t, int nt) {
  return {balanced_cut(work, row_work, n, t, nt), balanced_cut(work, row_work, n, t + 1, nt)};
}

/// The rows of the half list one thread takes in force_loop: [begin, end). A thread writes forces
/// only to particles from its first row on (each pair is listed under its smaller index), which
/// is what lets force_loop clear and sum no more of a thread's buffer than that.
struct ThreadRows {
  std::size_t begin = 0, end = 0;
};

/// The first row of thread k of nt (k = nt: n): balanced_cut on the work prefix of the last list
/// build, or on the listed pairs alone (plus list.work.row a row) when rows changed since.
inline std::size_t first_row(const VerletList& list, std::size_t n, int k, int nt) {
  const bool weighed = list.work_offset.size() == n + 1;
  return balanced_cut(weighed ? list.work_offset.data() : list.offset.data(), weighed ? 0 : list.work.row, n, k, nt);
}

}  // namespace gravsweep

// What the pair loops of force_loop.h are given and how they find their pairs: the force pass's
// context (ForceContext), the overlap failure it records, and the one pair filter of both
// particle-particle paths (filter_listed_pairs), which writes the touching pairs of a thread's
// rows of the half list into a TouchingBuffer (the scalar path) or a law's batch.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/core/particles.h"
#include "engine/geometry/walls.h"
#include "engine/neighbor/verlet_list.h"
#include "engine/system/system.h"
#include "engine/system/thread_rows.h"

namespace gravsweep {
/// Overlap beyond this fraction of the smaller radius is a numerical failure.
inline constexpr double kMaxOverlapFraction = 0.5;

/// The deepest overlap beyond kMaxOverlapFraction seen in a force pass: a particle against another
/// particle or against a wall (the System turns it into a NumericalFailure naming both).
struct OverlapFailure {
  double ratio = 0;         ///< overlap / smaller radius
  long long particle = -1;  ///< -1: no failure
  long long other = -1;     ///< the other particle, or -1 when it is a wall
  long long wall = -1;      ///< the wall's index when the other side is a wall
  bool failed() const { return particle >= 0; }
  void consider(double r, long long i, long long j, long long w) {
    if (r > kMaxOverlapFraction && r > ratio) *this = OverlapFailure{r, i, j, w};
  }
};

struct ForceContext {
  Particles& p;
  const std::vector<Wall>& walls;
  VerletList& nlist;
  std::vector<ContactHistory>& wall_history;          ///< [candidate]
  std::vector<FrameHistory>& wall_frame_history;      ///< [candidate], or empty
  const std::vector<std::uint32_t>& wall_candidates;  ///< particle * walls + wall
  const PairTable& pairs;
  const ContactOptions& options;
  std::vector<std::vector<Vec3>>& thread_force;
  std::vector<std::vector<Vec3>>& thread_torque;
  Vec3 gravity_m_s2;
  double dt_s;
  bool use_eval_velocities;
  bool track_energy;
  int threads;
  std::uint32_t filter_min_pairs;  ///< SystemConfig::pair_filter_min_pairs
  /// Set inside System::step: the integrator's end of step runs on each thread's share right
  /// after the force sums (one parallel region a step), its findings merged into *check.
  const Integrator* finish = nullptr;
  StepCheck* check = nullptr;
  RegionTiming* timing = nullptr;  ///< System::set_region_timing: where the region's time goes
  // Outputs.
  StepStats stats{};
  OverlapFailure failure{};
};

/// A touching pair of the half list, as for_each_touching_pair hands it on: list slot k, the
/// particles i < j's partner, the centre offset d = x_j - x_i (m), |d|^2 and the effective mass.
struct TouchingPair {
  std::uint32_t k, i, j;
  Vec3 d_m;
  double dist2_m2, m_eff_kg;
};

/// The touching pairs of a stretch of the half list, in list order, as filter_listed_pairs leaves
/// them for the scalar path's visits: slot, particles, centre offset, |d|^2.
struct TouchingBuffer {
  static constexpr int kSize = 64;
  int count = 0;
  std::uint32_t k[kSize], i[kSize], j[kSize];
  Vec3 d_m[kSize];
  double dist2_m2[kSize];
  /// Writes slot `count` (kept when the filter advances `count`): list slot kk, particles ii < jj,
  /// centre offset d = x_j - x_i (m), |d|^2.
  GRAVSWEEP_INLINE void put(std::uint32_t kk, std::uint32_t ii, std::uint32_t jj, const Vec3& d, double d2) {
    k[count] = kk;
    i[count] = ii;
    j[count] = jj;
    d_m[count] = d;
    dist2_m2[count] = d2;
  }
  [[nodiscard]] bool full() const { return count == kSize; }
};

/// What both ways of for_each_touching_pair do with a touching pair (slot k, rows i < j with
/// radius ri of i, centre offset d = x_j - x_i, |d|^2): skip two fixed particles, record an
/// overlap beyond kMaxOverlapFraction in `worst`, and visit the rest with their effective mass.
template <class Visit>
GRAVSWEEP_INLINE void visit_touching(const Particles& p, ContactHistory* hist, std::uint32_t k, std::uint32_t i,
                                     std::uint32_t j, double ri, const Vec3& d, double dist2, OverlapFailure& worst,
                                     Visit&& visit) {
  const double* R = p.radius_m.data();
  const double* M = p.mass_kg.data();
  const double* inv_m = p.inv_mass_1_kg.data();
  if (inv_m[i] == 0 && inv_m[j] == 0) return;  // two fixed particles
  const double rsum = ri + R[j];
  const double r_min = std::min(ri, R[j]);
  const double limit = rsum - kMaxOverlapFraction * r_min;
  if (dist2 < limit * limit) worst.consider((rsum - std::sqrt(dist2)) / r_min, static_cast<long long>(i), j, -1);
  const double mi = inv_m[i] == 0 ? kInf : M[i], mj = inv_m[j] == 0 ? kInf : M[j];
  visit(TouchingPair{k, i, j, d, dist2, effective_mass_kg(mi, mj)}, hist[k]);
}

/// The pair filter of both particle-particle paths: rows [row_begin, row_end) of the half
/// neighbour list, this thread's share (force_loop cuts it with balanced_cut). Each listed pair
/// that touches is written into the next slot of `lanes` (a TouchingBuffer or a law's batch:
/// put(k, i, j, d, |d|^2) writes slot `count`, which only a touching pair keeps), in list order;
/// a listed pair that no longer touches has its history erased; drain() empties full lanes (and
/// sets count to 0), and the last ones. kFilter (a share of at least c.filter_min_pairs listed
/// pairs, filter_pairs): the slot is written whether or not the pair touches, without a branch on
/// the distance test (whether a listed pair touches is a coin toss at rest, about 60 % of the
/// listed pairs); otherwise a branch per listed pair. Always inlined: called through a lambda,
/// the lanes of the caller would otherwise be read through references on every pair (slower on
/// the 1 g drop, measured: docs/history/benchmarks.md).
template <bool kFilter, class Lanes, class Drain>
GRAVSWEEP_INLINE void filter_listed_pairs(ForceContext& c, std::size_t row_begin, std::size_t row_end, Lanes& lanes,
                                          Drain&& drain) {
  const Particles& p = c.p;
  const Vec3* X = p.position_m.data();
  const double* R = p.radius_m.data();
  const std::uint32_t* off = c.nlist.offset.data();
  const std::uint32_t* nbr = c.nlist.neighbor.data();
  ContactHistory* hist = c.nlist.history.data();
  for (std::size_t i = row_begin; i < row_end; ++i) {
    const Vec3 xi = X[i];
    const double ri = R[i];
    for (std::uint32_t k = off[i]; k < off[i + 1]; ++k) {
      const std::uint32_t j = nbr[k];
      const Vec3 d = X[j] - xi;
      const double rsum = ri + R[j];
      const double dist2 = d.squaredNorm();
      const bool touching = dist2 < rsum * rsum;
      ContactHistory& h = hist[k];
      if constexpr (kFilter) {
        if (h.active & !touching) h.active = false;                // contact ended: history erased (no write otherwise)
        lanes.put(k, static_cast<std::uint32_t>(i), j, d, dist2);  // kept only when touching
        lanes.count += static_cast<int>(touching);
      } else {
        if (!touching) {
          if (h.active) h.active = false;  // contact ended: history erased (no write otherwise)
          continue;
        }
        lanes.put(k, static_cast<std::uint32_t>(i), j, d, dist2);
        ++lanes.count;
      }
      if (lanes.full()) drain();
    }
  }
  if (lanes.count > 0) drain();
}

/// The scalar path's pairs: filter_listed_pairs into a TouchingBuffer, each touching pair then
/// visited in list order (visit_touching): two fixed particles are skipped, an overlap beyond
/// kMaxOverlapFraction is recorded in `worst` (the exact ratio computed only then), and
/// visit(const TouchingPair&, ContactHistory&) evaluates the rest.
template <bool kFilter, class Visit>
GRAVSWEEP_INLINE void for_each_touching_pair(ForceContext& c, std::size_t row_begin, std::size_t row_end,
                                             OverlapFailure& worst, Visit&& visit) {
  const Particles& p = c.p;
  const double* R = p.radius_m.data();
  ContactHistory* hist = c.nlist.history.data();
  TouchingBuffer buf;
  filter_listed_pairs<kFilter>(c, row_begin, row_end, buf, [&]() GRAVSWEEP_INLINE_LAMBDA {
    for (int b = 0; b < buf.count; ++b)
      visit_touching(p, hist, buf.k[b], buf.i[b], buf.j[b], R[buf.i[b]], buf.d_m[b], buf.dist2_m2[b], worst, visit);
    buf.count = 0;
  });
}

/// True when this thread's rows hold at least c.filter_min_pairs listed pairs: its pair loop
/// then filters (for_each_touching_pair<true>). Each way is its own instantiation of the pair
/// loop: with both inlined into one function the branch-per-pair way ran slower on the
/// paper's bed (BENCHMARKS.md).
inline bool filter_pairs(const ForceContext& c, const ThreadRows& rows) {
  const std::uint32_t* off = c.nlist.offset.data();
  return rows.end > rows.begin && off[rows.end] - off[rows.begin] >= c.filter_min_pairs;
}

}  // namespace gravsweep

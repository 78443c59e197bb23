// The one pair loop, written once and templated on the contact law and the rolling model, so the
// contact loop has no virtual call. Half neighbour list; each OpenMP thread accumulates into its own
// force/torque buffer, then buffers are summed in a fixed order: results are deterministic for a
// given thread count.
#pragma once
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "engine/system/finish_queue.h"
#include "engine/system/hertz_batch.h"
#include "engine/system/pair_filter.h"
#include "engine/system/thread_rows.h"
#include "engine/core/particles.h"
#include "engine/geometry/walls.h"
#include "engine/neighbor/verlet_list.h"
#include "engine/system/system.h"

namespace gravsweep {

/// One contact through the law and the rolling model: a new contact (history not active) starts
/// with empty frame springs; adds the normal elastic energy when tracked.
template <class Law, class Rolling>
GRAVSWEEP_INLINE void evaluate_contact(const ContactGeometry& g, const PairCoefficients& pc, const ForceContext& c,
                                       ContactHistory& h, FrameHistory& fh, ContactForce& out, double& energy) {
  if (!h.active) fh = FrameHistory{};
  Law::evaluate(g, pc, c.options, h, fh, c.dt_s, out);
  Rolling::apply(g, pc, c.options, h, fh, c.dt_s, out);
  if (c.track_energy) energy += Law::normal_energy_J(g, pc);
}

/// A law's batched kernel for this rolling model: Law::Batch, when the law names one and
/// Batch::supports<Rolling> (hertz with sunday or none rolling); otherwise the scalar loop.
template <class Law, class Rolling, class = void>
struct HasBatch : std::false_type {};
template <class Law, class Rolling>
struct HasBatch<Law, Rolling, std::void_t<typename Law::Batch>>
    : std::bool_constant<Law::Batch::template supports<Rolling>> {};
template <class Law, class Rolling>
inline constexpr bool kHasBatch = HasBatch<Law, Rolling>::value;

/// The rest of a batch's lanes, once the pair filter has written each touching pair's slot,
/// particles and centre offset (HertzBatch::put): drops a pair of two fixed particles (lanes
/// after it move up one), records an overlap beyond kMaxOverlapFraction in `worst`, and gathers
/// radii, masses, velocities, spins, coefficients and history (HertzBatch::fill). The
/// same arithmetic and list order as visit_touching: results bit for bit those of the per-pair
/// path. A separate pass over the lanes, so that the filter writes each pair once.
template <class Batch>
GRAVSWEEP_INLINE void gather_lanes(const ForceContext& c, const Vec3* V, const Vec3* W, Batch& batch,
                                   OverlapFailure& worst) {
  const Particles& p = c.p;
  const double* R = p.radius_m.data();
  const double* M = p.mass_kg.data();
  const double* inv_m = p.inv_mass_1_kg.data();
  const std::uint8_t* mat = p.material.data();
  const ContactHistory* hist = c.nlist.history.data();
  int kept = 0;
  for (int b = 0; b < batch.count; ++b) {
    const std::uint32_t i = batch.i[b], j = batch.j[b];
    if (inv_m[i] == 0 && inv_m[j] == 0) continue;  // two fixed particles
    if (kept != b) batch.move_lane(b, kept);
    const double ri = R[i], rj = R[j], dist2 = batch.dist2[kept];
    const double rsum = ri + rj;
    const double r_min = std::min(ri, rj);
    const double limit = rsum - kMaxOverlapFraction * r_min;
    if (dist2 < limit * limit) worst.consider((rsum - std::sqrt(dist2)) / r_min, static_cast<long long>(i), j, -1);
    const double mi = inv_m[i] == 0 ? kInf : M[i], mj = inv_m[j] == 0 ? kInf : M[j];
    batch.fill(kept, ri, rj, mi, mj, V[i], V[j], W[i], W[j], c.pairs(mat[i], mat[j]), hist[batch.k[kept]]);
    ++kept;
  }
  batch.count = kept;
}

/// The particle-particle part of force_loop for a law with a Batch (kHasBatch): the pair filter
/// (filter_listed_pairs) writes each listed pair's slot, particles and centre offset straight into
/// the batch's next lane; a full batch is gathered (gather_lanes), evaluated vectorised and
/// scattered back in list order.
template <class Batch, bool kRolling, bool kFilter>
void pair_loop_batched(ForceContext& c, const ThreadRows& rows, Vec3* F, Vec3* T, long long& contacts, double& energy,
                       OverlapFailure& worst) {
  const Particles& p = c.p;
  const Vec3* V = c.use_eval_velocities ? p.eval_velocity_m_s.data() : p.velocity_m_s.data();
  const Vec3* W = c.use_eval_velocities ? p.eval_omega_rad_s.data() : p.omega_rad_s.data();
  ContactHistory* hist = c.nlist.history.data();
  Batch batch;
  auto flush = [&]() GRAVSWEEP_INLINE_LAMBDA {
    gather_lanes(c, V, W, batch, worst);
    batch.template compute<kRolling>(c.options, c.dt_s);
    for (int b = 0; b < batch.count; ++b) {
      ContactHistory& h = hist[batch.k[b]];
      h.shear_m = Vec3(batch.sx[b], batch.sy[b], batch.sz[b]);
      h.duration_s = batch.duration[b];
      h.gate_s = batch.gate[b];
      h.active = true;
      const Vec3 f(batch.fx[b], batch.fy[b], batch.fz[b]);
      const std::uint32_t i = batch.i[b], j = batch.j[b];
      F[i] -= f;
      F[j] += f;
      T[i] += Vec3(batch.t1x[b], batch.t1y[b], batch.t1z[b]);
      T[j] += Vec3(batch.t2x[b], batch.t2y[b], batch.t2z[b]);
    }
    if (c.track_energy)
      for (int b = 0; b < batch.count; ++b) {
        energy += HertzChrono::normal_energy_J(batch.E[b], batch.R_eff[b], batch.overlap[b]);
      }
    contacts += batch.count;
    batch.count = 0;
  };
  filter_listed_pairs<kFilter>(c, rows.begin, rows.end, batch, flush);
}

/// The particle-particle part of force_loop for every other (law, rolling) pair: one contact at
/// a time through evaluate_contact.
template <class Law, class Rolling, bool kFilter>
void pair_loop_scalar(ForceContext& c, const ThreadRows& rows, Vec3* F, Vec3* T, long long& contacts, double& energy,
                      OverlapFailure& worst) {
  constexpr bool kFrames = Law::uses_frame_history || Rolling::uses_frame_history;
  const Particles& p = c.p;
  const Vec3* V = c.use_eval_velocities ? p.eval_velocity_m_s.data() : p.velocity_m_s.data();
  const Vec3* W = c.use_eval_velocities ? p.eval_omega_rad_s.data() : p.omega_rad_s.data();
  const double* R = p.radius_m.data();
  const std::uint8_t* mat = p.material.data();
  FrameHistory* frames = kFrames ? c.nlist.frame_history.data() : nullptr;
  ContactForce out;
  ContactGeometry g;
  FrameHistory scratch;  // frame histories are stored only when a model reads them
  for_each_touching_pair<kFilter>(c, rows.begin, rows.end, worst, [&](const TouchingPair& t, ContactHistory& h) {
    const std::uint32_t i = t.i, j = t.j;
    const double dist = std::sqrt(t.dist2_m2);
    const double rsum = R[i] + R[j];
    g.n = t.d_m / dist;
    g.overlap_m = rsum - dist;
    g.distance_m = dist;
    g.r1_m = R[i];
    g.r2_m = R[j];
    g.R_eff_m = R[i] * R[j] / rsum;
    g.m_eff_kg = t.m_eff_kg;
    g.v1 = V[i];
    g.v2 = V[j];
    g.w1 = W[i];
    g.w2 = W[j];
    g.wall = false;
    evaluate_contact<Law, Rolling>(g, c.pairs(mat[i], mat[j]), c, h, kFrames ? frames[t.k] : scratch, out, energy);
    F[i] -= out.force_on_2;
    F[j] += out.force_on_2;
    T[i] += out.torque_1;
    T[j] += out.torque_2;
    ++contacts;
  });
}

/// Particle-wall contacts: the wall candidates (particle, wall) of this thread's rows, so that a
/// thread writes only to particles from its first row on (force_loop sums no more than that).
template <class Law, class Rolling>
void wall_loop(ForceContext& c, const ThreadRows& rows, Vec3* F, Vec3* T, long long& wall_contacts, double& energy,
               OverlapFailure& worst) {
  constexpr bool kFrames = Law::uses_frame_history || Rolling::uses_frame_history;
  const std::size_t n_walls = c.walls.size();
  if (n_walls == 0) return;
  const Particles& p = c.p;
  const Vec3* V = c.use_eval_velocities ? p.eval_velocity_m_s.data() : p.velocity_m_s.data();
  const Vec3* W = c.use_eval_velocities ? p.eval_omega_rad_s.data() : p.omega_rad_s.data();
  const Vec3* X = p.position_m.data();
  const double* R = p.radius_m.data();
  const double* M = p.mass_kg.data();
  const std::uint8_t* mat = p.material.data();
  FrameHistory* wall_frames = kFrames ? c.wall_frame_history.data() : nullptr;
  ContactForce out;
  ContactGeometry g;
  FrameHistory scratch;
  // Candidate codes are particle * walls + wall, increasing.
  auto below = [](std::uint32_t code, std::uint64_t bound) { return code < bound; };
  const auto first =
      std::lower_bound(c.wall_candidates.begin(), c.wall_candidates.end(), std::uint64_t{rows.begin} * n_walls, below);
  const auto last = std::lower_bound(first, c.wall_candidates.end(), std::uint64_t{rows.end} * n_walls, below);
  const auto k_end = static_cast<std::size_t>(last - c.wall_candidates.begin());
  for (auto k = static_cast<std::size_t>(first - c.wall_candidates.begin()); k < k_end; ++k) {
    const std::uint32_t code = c.wall_candidates[k];
    const std::size_t i = code / n_walls, w = code - i * n_walls;  // one division
    ContactHistory& h = c.wall_history[k];
    WallTouch touch;
    if (!touch_wall(c.walls[w], X[i], R[i], touch)) {
      if (h.active) h.active = false;
      continue;
    }
    g.n = touch.n;
    g.overlap_m = touch.overlap_m;
    g.distance_m = touch.distance_m;
    g.r1_m = R[i];
    g.r2_m = kInf;
    g.R_eff_m = touch.R_eff_m;
    g.m_eff_kg = M[i];
    g.v1 = V[i];
    g.v2.setZero();
    g.w1 = W[i];
    g.w2.setZero();
    g.wall = true;
    worst.consider(touch.overlap_m / R[i], static_cast<long long>(i), -1, static_cast<long long>(w));
    evaluate_contact<Law, Rolling>(g, c.pairs(mat[i], c.walls[w].material), c, h, kFrames ? wall_frames[k] : scratch,
                                   out, energy);
    F[i] -= out.force_on_2;
    T[i] += out.torque_1;
    ++wall_contacts;
  }
}

/// What one thread of force_loop counts and finds, in its own cache line: combined in thread
/// order after the parallel region instead of through an OpenMP reduction and a critical section,
/// whose locks both threads reached in the same microsecond every step (futex calls: 40,093 before,
/// 35,941 after in 8,000 steps of the 0.1 m/s2 drop; BENCHMARKS.md). The fixed order also makes
/// the tracked elastic energy the same sum for any thread count.
struct alignas(64) ThreadTally {
  long long contacts = 0, wall_contacts = 0;
  double energy_J = 0;
  // ForceContext::timing set: seconds of the pair and wall loops, of waiting for a ready block
  // after them (FinishQueue), and of the sums and end of step.
  double pair_loops_s = 0, pair_barrier_s = 0, sums_s = 0;
  OverlapFailure worst;
  StepFindings found;
};

/// Particles per block of force_loop's sum + end of step: the block's force and torque sums
/// (48 bytes a particle) stay in L1 until the integrator reads them.
inline constexpr std::size_t kFinishBlock = 256;

/// Adds thread t's force and torque buffers (t >= 1) to particle i's sums, for the threads whose
/// rows begin at or before i (the others never write to i: their buffers hold zeros there, and
/// adding them would change no bit).
GRAVSWEEP_INLINE void add_thread_sums(const ForceContext& c, const std::size_t* first, int nt, std::size_t i, Vec3& f,
                                      Vec3& tq) {
  for (int tt = 1; tt < nt && first[tt] <= i; ++tt) {
    f += c.thread_force[tt][i];
    tq += c.thread_torque[tt][i];
  }
}

/// One force evaluation: particle-particle and particle-wall contacts, each thread on its rows
/// (cut by work, balanced_cut) into its own buffer; the buffers summed with gravity in a fixed
/// order (deterministic for a given thread count); then, inside the same parallel region, the
/// integrator's end of step on the same blocks when c.finish is set (FinishQueue).
template <class Law, class Rolling>
void force_loop(ForceContext& c) {
  Particles& p = c.p;
  const std::size_t n = p.size();
  const double* M = p.mass_kg.data();
  const double* inv_m = p.inv_mass_1_kg.data();
  // One tally per thread, combined in thread order after the region (no lock in the region). A
  // team smaller than asked leaves tallies untouched: zeros, which add nothing to the combination.
  std::vector<ThreadTally> tally(static_cast<std::size_t>(std::max(1, c.threads)));
  const bool timed = c.timing != nullptr;
  const double region_start_s = timed ? omp_get_wtime() : 0;
  int team = 1;
  FinishQueue queue(c.threads);

#pragma omp parallel num_threads(c.threads)
  {
    const int t = omp_get_thread_num();
    const int nt = omp_get_num_threads();
    ThreadTally& mine = tally[static_cast<std::size_t>(t)];
    const double work_start_s = timed ? omp_get_wtime() : 0;
    if (t == 0) team = nt;
    thread_local std::vector<std::size_t> first;  // first row of each thread, and n
    first.resize(static_cast<std::size_t>(nt) + 1);
    for (int k = 0; k <= nt; ++k) first[static_cast<std::size_t>(k)] = first_row(c.nlist, n, k, nt);
    const ThreadRows rows{first[static_cast<std::size_t>(t)], first[static_cast<std::size_t>(t) + 1]};
    // Thread 0 accumulates straight into the particles' force and torque arrays (one buffer pair
    // per extra thread; the sum below keeps the order gravity + thread 0 + thread 1 + ...), and
    // clears them whole; thread t >= 1 clears its buffers from its first row on (zeroing them as
    // the sum reads them instead was slower, docs/history/benchmarks.md).
    // Nothing reads force_N / torque_N_m between here and the sum.
    Vec3* F = t == 0 ? p.force_N.data() : c.thread_force[t].data();
    Vec3* T = t == 0 ? p.torque_N_m.data() : c.thread_torque[t].data();
    std::fill(F + rows.begin, F + n, Vec3::Zero());
    std::fill(T + rows.begin, T + n, Vec3::Zero());
    if constexpr (kHasBatch<Law, Rolling>) {
      using Batch = typename Law::Batch;
      constexpr bool kRolling = Batch::template with_rolling<Rolling>;
      if (filter_pairs(c, rows))
        pair_loop_batched<Batch, kRolling, true>(c, rows, F, T, mine.contacts, mine.energy_J, mine.worst);
      else
        pair_loop_batched<Batch, kRolling, false>(c, rows, F, T, mine.contacts, mine.energy_J, mine.worst);
    } else {
      if (filter_pairs(c, rows))
        pair_loop_scalar<Law, Rolling, true>(c, rows, F, T, mine.contacts, mine.energy_J, mine.worst);
      else
        pair_loop_scalar<Law, Rolling, false>(c, rows, F, T, mine.contacts, mine.energy_J, mine.worst);
    }
    wall_loop<Law, Rolling>(c, rows, F, T, mine.wall_contacts, mine.energy_J, mine.worst);
    const double loops_end_s = timed ? omp_get_wtime() : 0;
    queue.mark_done(t);
    // Sum the thread buffers in a fixed order and add gravity (same parallel region), block by
    // block as they become ready; then finish the step on the same block (a particle's update
    // reads only its own sums).
    StepFindings& found = mine.found;
    double waited_s = 0;
    for (;;) {
      const std::size_t b = queue.next_block.fetch_add(1, std::memory_order_relaxed) * kFinishBlock;
      if (b >= n) break;
      const std::size_t e = std::min(n, b + kFinishBlock);
      const double wait_start_s = timed ? omp_get_wtime() : 0;
      if (queue.wait_ready(first.data(), nt, e) && timed) waited_s += omp_get_wtime() - wait_start_s;
      for (std::size_t i = b; i < e; ++i) {
        // The same expression as with a buffer for thread 0 (gravity first, then each thread's
        // sum): contraction into FMAs and rounding stay those of the former layout.
        Vec3 f = inv_m[i] > 0 ? Vec3(M[i] * c.gravity_m_s2) : Vec3::Zero();
        Vec3 tq = Vec3::Zero();
        f += p.force_N[i];
        tq += p.torque_N_m[i];
        add_thread_sums(c, first.data(), nt, i, f, tq);
        p.force_N[i] = f;
        p.torque_N_m[i] = tq;
      }
      // The block's sums are still in L1 when the integrator reads them back.
      if (c.finish != nullptr) c.finish->end_range(p, c.dt_s, *c.check, b, e, found);
    }
    if (timed) {
      mine.pair_loops_s = loops_end_s - work_start_s;
      mine.pair_barrier_s = waited_s;
      mine.sums_s = omp_get_wtime() - loops_end_s - waited_s;
    }
  }
  if (timed) {
    c.timing->wall_s += omp_get_wtime() - region_start_s;
    for (std::size_t t = 0; t < tally.size(); ++t) {
      c.timing->busy_s += tally[t].pair_loops_s + tally[t].sums_s;
      c.timing->pair_barrier_wait_s += tally[t].pair_barrier_s;
      if (t < c.timing->pair_loops_s.size()) c.timing->pair_loops_s[t] += tally[t].pair_loops_s;
    }
    c.timing->threads = team;
    ++c.timing->regions;
  }
  c.stats = StepStats{};
  for (const ThreadTally& x : tally) {
    c.stats.contacts += x.contacts;
    c.stats.wall_contacts += x.wall_contacts;
    c.stats.elastic_energy_J += x.energy_J;
    if (x.worst.failed() && x.worst.ratio > c.failure.ratio) c.failure = x.worst;
    if (c.finish != nullptr) c.check->merge(x.found);
  }
}

}  // namespace gravsweep

// The one pair loop, written once and templated on the contact law and the rolling model, so the
// contact loop has no virtual call. Half neighbour list; each OpenMP thread accumulates into its own
// force/torque buffer, then buffers are summed in a fixed order: results are deterministic for a
// given thread count.
#pragma once
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "engine/contact/hertz_batch.h"
#include "engine/core/particles.h"
#include "engine/geometry/walls.h"
#include "engine/neighbor/verlet_list.h"
#include "engine/system/system.h"

namespace gravsweep {

struct ForceContext {
  Particles& p;
  const std::vector<Wall>& walls;
  VerletList& nlist;
  std::vector<ContactHistory>& wall_history;        ///< [candidate]
  std::vector<FrameHistory>& wall_frame_history;   ///< [candidate], or empty
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
  // Outputs.
  StepStats stats{};
  long long failed_particle = -1;
  long long failed_other = -1;
  double failed_overlap_ratio = 0;
};

/// Overlap beyond this fraction of the smaller radius is a numerical failure.
inline constexpr double kMaxOverlapFraction = 0.5;

/// The particle-particle part of force_loop for the laws HertzBatch evaluates (hertz with sunday
/// or none rolling): this thread's share of the list (the same static partition as the scalar
/// loop) is filtered into batches of touching pairs, evaluated vectorised, and scattered back in
/// list order. Called inside force_loop's parallel region (orphaned `omp for`).
template <bool kRolling>
void pair_loop_batched(ForceContext& c, Vec3* F, Vec3* T, long long& contacts, double& energy,
                       double& my_ratio, long long& my_bad_i, long long& my_bad_j) {
  Particles& p = c.p;
  const std::size_t n = p.size();
  const Vec3* V = c.use_eval_velocities ? p.eval_velocity_m_s.data() : p.velocity_m_s.data();
  const Vec3* W = c.use_eval_velocities ? p.eval_omega_rad_s.data() : p.omega_rad_s.data();
  const Vec3* X = p.position_m.data();
  const double* R = p.radius_m.data();
  const double* M = p.mass_kg.data();
  const double* inv_m = p.inv_mass_1_kg.data();
  const std::uint8_t* mat = p.material.data();
  const std::uint32_t* off = c.nlist.offset.data();
  const std::uint32_t* nbr = c.nlist.neighbor_.data();
  ContactHistory* hist = c.nlist.history.data();
  HertzBatch batch;
  auto flush = [&] {
    batch.compute<kRolling>(c.options, c.dt_s);
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
        const double d = batch.overlap[b];
        energy += (8.0 / 15.0) * batch.E[b] * std::sqrt(batch.R_eff[b]) * d * d * std::sqrt(d);
      }
    contacts += batch.count;
    batch.count = 0;
  };
#pragma omp for schedule(static) nowait
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 xi = X[i];
    const double ri = R[i];
    for (std::uint32_t k = off[i]; k < off[i + 1]; ++k) {
      const std::uint32_t j = nbr[k];
      const Vec3 d = X[j] - xi;
      const double rsum = ri + R[j];
      const double dist2 = d.squaredNorm();
      ContactHistory& h = hist[k];
      if (dist2 >= rsum * rsum) {
        if (h.active) h.active = false;  // contact ended: history erased (no write otherwise)
        continue;
      }
      if (inv_m[i] == 0 && inv_m[j] == 0) continue;  // two fixed particles
      // Overlap beyond kMaxOverlapFraction of the smaller radius: exact ratio only then.
      const double r_min = std::min(ri, R[j]);
      const double limit = rsum - kMaxOverlapFraction * r_min;
      if (dist2 < limit * limit) {
        const double ratio = (rsum - std::sqrt(dist2)) / r_min;
        if (ratio > kMaxOverlapFraction && ratio > my_ratio) {
          my_ratio = ratio;
          my_bad_i = static_cast<long long>(i);
          my_bad_j = j;
        }
      }
      const double mi = inv_m[i] == 0 ? kInf : M[i], mj = inv_m[j] == 0 ? kInf : M[j];
      const double m_eff = std::isinf(mi) ? mj : std::isinf(mj) ? mi : mi * mj / (mi + mj);
      batch.add(k, static_cast<std::uint32_t>(i), j, d, dist2, ri, R[j], m_eff, V[i], V[j], W[i], W[j],
                c.pairs(mat[i], mat[j]), h);
      if (batch.full()) flush();
    }
  }
  if (batch.count > 0) flush();
}

template <class Law, class Rolling>
void force_loop(ForceContext& c) {
  // Frame histories are stored only when a model reads them; the others get a scratch record.
  constexpr bool kFrames = Law::uses_frame_history || Rolling::uses_frame_history;
  Particles& p = c.p;
  const std::size_t n = p.size();
  const std::size_t n_walls = c.walls.size();
  const Vec3* V = c.use_eval_velocities ? p.eval_velocity_m_s.data() : p.velocity_m_s.data();
  const Vec3* W = c.use_eval_velocities ? p.eval_omega_rad_s.data() : p.omega_rad_s.data();
  const Vec3* X = p.position_m.data();
  const double* R = p.radius_m.data();
  const double* M = p.mass_kg.data();
  const double* inv_m = p.inv_mass_1_kg.data();
  const std::uint8_t* mat = p.material.data();
  const std::uint32_t* off = c.nlist.offset.data();
  const std::uint32_t* nbr = c.nlist.neighbor_.data();
  ContactHistory* hist = c.nlist.history.data();
  FrameHistory* frames = kFrames ? c.nlist.frame_history.data() : nullptr;
  FrameHistory* wall_frames = kFrames ? c.wall_frame_history.data() : nullptr;
  const double dt = c.dt_s;
  long long contacts = 0, wall_contacts = 0;
  double energy = 0;
  long long bad_i = -1, bad_j = -1;
  double bad_ratio = 0;

#pragma omp parallel num_threads(c.threads) reduction(+ : contacts, wall_contacts, energy)
  {
    const int t = omp_get_thread_num();
    // Thread 0 accumulates straight into the particles' force and torque arrays (one buffer pair
    // per extra thread; the sum below keeps the order gravity + thread 0 + thread 1 + ...).
    // Nothing reads force_N / torque_N_m between here and the sum.
    Vec3* F = t == 0 ? p.force_N.data() : c.thread_force[t].data();
    Vec3* T = t == 0 ? p.torque_N_m.data() : c.thread_torque[t].data();
    std::fill(F, F + n, Vec3::Zero());
    std::fill(T, T + n, Vec3::Zero());
    long long my_bad_i = -1, my_bad_j = -1;
    double my_ratio = 0;
    ContactForce out;
    ContactGeometry g;
    FrameHistory scratch;
    if constexpr (kHasHertzBatch<Law, Rolling>) {
      pair_loop_batched<std::is_same_v<Rolling, RollingSunday>>(c, F, T, contacts, energy, my_ratio, my_bad_i, my_bad_j);
    } else {
  #pragma omp for schedule(static) nowait
      for (std::size_t i = 0; i < n; ++i) {
        const Vec3 xi = X[i];
        const double ri = R[i];
        for (std::uint32_t k = off[i]; k < off[i + 1]; ++k) {
          const std::uint32_t j = nbr[k];
          const Vec3 d = X[j] - xi;
          const double rsum = ri + R[j];
          const double dist2 = d.squaredNorm();
          ContactHistory& h = hist[k];
          if (dist2 >= rsum * rsum) {
            if (h.active) h.active = false;  // contact ended: history erased (no write otherwise)
            continue;
          }
          if (inv_m[i] == 0 && inv_m[j] == 0) continue;  // two fixed particles
          const double dist = std::sqrt(dist2);
          g.n = d / dist;
          g.overlap_m = rsum - dist;
          g.distance_m = dist;
          g.r1_m = ri;
          g.r2_m = R[j];
          g.R_eff_m = ri * R[j] / rsum;
          const double mi = inv_m[i] == 0 ? kInf : M[i], mj = inv_m[j] == 0 ? kInf : M[j];
          g.m_eff_kg = std::isinf(mi) ? mj : std::isinf(mj) ? mi : mi * mj / (mi + mj);
          g.v1 = V[i];
          g.v2 = V[j];
          g.w1 = W[i];
          g.w2 = W[j];
          g.wall = false;
          const double ratio = g.overlap_m / std::min(ri, R[j]);
          if (ratio > kMaxOverlapFraction && ratio > my_ratio) {
            my_ratio = ratio;
            my_bad_i = i;
            my_bad_j = j;
          }
          const PairCoefficients& pc = c.pairs(mat[i], mat[j]);
          FrameHistory& fh = kFrames ? frames[k] : scratch;
          if (!h.active) fh = FrameHistory{};  // a new contact starts with empty springs
          Law::evaluate(g, pc, c.options, h, fh, dt, out);
          Rolling::apply(g, pc, c.options, h, fh, dt, out);
          F[i] -= out.force_on_2;
          F[j] += out.force_on_2;
          T[i] += out.torque_1;
          T[j] += out.torque_2;
          ++contacts;
          if (c.track_energy) energy += Law::normal_energy_J(g, pc);
        }
      }
    }
    if (n_walls > 0) {
      const std::size_t n_cand = c.wall_candidates.size();
#pragma omp for schedule(static) nowait
      for (std::size_t k = 0; k < n_cand; ++k) {
        const std::uint32_t code = c.wall_candidates[k];
        const std::size_t i = code / n_walls, w = code % n_walls;
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
        const double ratio = touch.overlap_m / R[i];
        if (ratio > kMaxOverlapFraction && ratio > my_ratio) {
          my_ratio = ratio;
          my_bad_i = static_cast<long long>(i);
          my_bad_j = -2 - static_cast<long long>(w);
        }
        const PairCoefficients& pc = c.pairs(mat[i], c.walls[w].material);
        FrameHistory& fh = kFrames ? wall_frames[k] : scratch;
        if (!h.active) fh = FrameHistory{};
        Law::evaluate(g, pc, c.options, h, fh, dt, out);
        Rolling::apply(g, pc, c.options, h, fh, dt, out);
        F[i] -= out.force_on_2;
        T[i] += out.torque_1;
        ++wall_contacts;
        if (c.track_energy) energy += Law::normal_energy_J(g, pc);
      }
    }
    if (my_bad_i >= 0) {
#pragma omp critical(gravsweep_force_failure)
      if (my_ratio > bad_ratio) {
        bad_ratio = my_ratio;
        bad_i = my_bad_i;
        bad_j = my_bad_j;
      }
    }
    // Sum the thread buffers in a fixed order and add gravity (same parallel region).
#pragma omp barrier
    const int nt = omp_get_num_threads();
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
      // The same expression as with a buffer for thread 0 (gravity first, then each thread's
      // sum): contraction into FMAs and rounding stay those of the former layout.
      Vec3 f = inv_m[i] > 0 ? Vec3(M[i] * c.gravity_m_s2) : Vec3::Zero();
      Vec3 tq = Vec3::Zero();
      f += p.force_N[i];
      tq += p.torque_N_m[i];
      for (int tt = 1; tt < nt; ++tt) {
        f += c.thread_force[tt][i];
        tq += c.thread_torque[tt][i];
      }
      p.force_N[i] = f;
      p.torque_N_m[i] = tq;
    }
  }
  c.stats.contacts = contacts;
  c.stats.wall_contacts = wall_contacts;
  c.stats.elastic_energy_J = energy;
  c.failed_particle = bad_i;
  c.failed_other = bad_j;
  c.failed_overlap_ratio = bad_ratio;
}

}  // namespace gravsweep

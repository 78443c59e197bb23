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

/// The pair skeleton every particle-particle path shares (scalar and batched): this thread's
/// static share of the half neighbour list (orphaned `omp for`, inside force_loop's parallel
/// region); a listed pair that no longer touches has its history erased; two fixed particles are
/// skipped; an overlap beyond kMaxOverlapFraction is recorded in `worst` (the exact ratio is
/// computed only then); visit(const TouchingPair&, ContactHistory&) evaluates the rest.
template <class Visit>
void for_each_touching_pair(ForceContext& c, OverlapFailure& worst, Visit&& visit) {
  const Particles& p = c.p;
  const std::size_t n = p.size();
  const Vec3* X = p.position_m.data();
  const double* R = p.radius_m.data();
  const double* M = p.mass_kg.data();
  const double* inv_m = p.inv_mass_1_kg.data();
  const std::uint32_t* off = c.nlist.offset.data();
  const std::uint32_t* nbr = c.nlist.neighbor.data();
  ContactHistory* hist = c.nlist.history.data();
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
      const double r_min = std::min(ri, R[j]);
      const double limit = rsum - kMaxOverlapFraction * r_min;
      if (dist2 < limit * limit) worst.consider((rsum - std::sqrt(dist2)) / r_min, static_cast<long long>(i), j, -1);
      const double mi = inv_m[i] == 0 ? kInf : M[i], mj = inv_m[j] == 0 ? kInf : M[j];
      const double m_eff = std::isinf(mi) ? mj : std::isinf(mj) ? mi : mi * mj / (mi + mj);
      visit(TouchingPair{k, static_cast<std::uint32_t>(i), j, d, dist2, m_eff}, h);
    }
  }
}

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

/// The particle-particle part of force_loop for the laws HertzBatch evaluates (hertz with sunday
/// or none rolling): the touching pairs of this thread's share are gathered into batches,
/// evaluated vectorised, and scattered back in list order.
template <bool kRolling>
void pair_loop_batched(ForceContext& c, Vec3* F, Vec3* T, long long& contacts, double& energy, OverlapFailure& worst) {
  const Particles& p = c.p;
  const Vec3* V = c.use_eval_velocities ? p.eval_velocity_m_s.data() : p.velocity_m_s.data();
  const Vec3* W = c.use_eval_velocities ? p.eval_omega_rad_s.data() : p.omega_rad_s.data();
  const double* R = p.radius_m.data();
  const std::uint8_t* mat = p.material.data();
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
  for_each_touching_pair(c, worst, [&](const TouchingPair& t, ContactHistory& h) {
    const std::uint32_t i = t.i, j = t.j;
    batch.add(t.k, i, j, t.d_m, t.dist2_m2, R[i], R[j], t.m_eff_kg, V[i], V[j], W[i], W[j], c.pairs(mat[i], mat[j]), h);
    if (batch.full()) flush();
  });
  if (batch.count > 0) flush();
}

/// The particle-particle part of force_loop for every other (law, rolling) pair: one contact at
/// a time through evaluate_contact.
template <class Law, class Rolling>
void pair_loop_scalar(ForceContext& c, Vec3* F, Vec3* T, long long& contacts, double& energy, OverlapFailure& worst) {
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
  for_each_touching_pair(c, worst, [&](const TouchingPair& t, ContactHistory& h) {
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

/// Particle-wall contacts: this thread's static share of the wall candidates (particle, wall).
template <class Law, class Rolling>
void wall_loop(ForceContext& c, Vec3* F, Vec3* T, long long& wall_contacts, double& energy, OverlapFailure& worst) {
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
    worst.consider(touch.overlap_m / R[i], static_cast<long long>(i), -1, static_cast<long long>(w));
    evaluate_contact<Law, Rolling>(g, c.pairs(mat[i], c.walls[w].material), c, h, kFrames ? wall_frames[k] : scratch,
                                   out, energy);
    F[i] -= out.force_on_2;
    T[i] += out.torque_1;
    ++wall_contacts;
  }
}

template <class Law, class Rolling>
void force_loop(ForceContext& c) {
  Particles& p = c.p;
  const std::size_t n = p.size();
  const double* M = p.mass_kg.data();
  const double* inv_m = p.inv_mass_1_kg.data();
  long long contacts = 0, wall_contacts = 0;
  double energy = 0;
  OverlapFailure worst;

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
    OverlapFailure mine;
    if constexpr (kHasHertzBatch<Law, Rolling>)
      pair_loop_batched<std::is_same_v<Rolling, RollingSunday>>(c, F, T, contacts, energy, mine);
    else
      pair_loop_scalar<Law, Rolling>(c, F, T, contacts, energy, mine);
    wall_loop<Law, Rolling>(c, F, T, wall_contacts, energy, mine);
    if (mine.failed()) {
#pragma omp critical(gravsweep_force_failure)
      if (mine.ratio > worst.ratio) worst = mine;
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
  c.failure = worst;
}

}  // namespace gravsweep

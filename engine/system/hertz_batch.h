// The particle-particle contacts of `hertz` (with `sunday` or `none` rolling) evaluated a batch at
// a time, structure of arrays, so the compiler vectorises the arithmetic across contacts (8
// doubles per AVX-512 instruction: the square roots and divisions that bound the scalar kernel
// run 8 at a time). The law is HertzChrono's: its stiffness and damping (HertzChrono::springs), gate
// (HertzChrono::gate_s) and spring energy are the same functions; the geometry, the tangential
// spring and RollingSunday::apply are written per lane (docs/physics/contact-laws.md sections
// 1.3-1.5), every branch a per-lane select. The force
// loop fills a batch with the touching pairs (gathering positions, velocities, coefficients and
// histories), calls compute(), then scatters forces, torques and histories back in the order of the
// list, so the sums keep the order of the scalar loop. Walls keep the scalar kernel.
//
// Rounding differs from the scalar kernel (reciprocals multiplied instead of three divisions,
// FMA contraction of other expressions): tests/unit/test_hertz_batch.cpp bounds the difference
// at 1e-12 relative on every branch (new contact, Coulomb slip, rolling gate, thresholds).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "engine/contact/contact.h"
#include "engine/contact/hertz_chrono.h"
#include "engine/core/material.h"
#include "engine/rolling/rolling_none.h"
#include "engine/rolling/rolling_sunday.h"

namespace gravsweep {

/// HertzChrono::Batch.
struct HertzBatch {
  /// The rolling models compute() evaluates with the law: sunday (with_rolling) and none.
  template <class Rolling>
  static constexpr bool supports = std::is_same_v<Rolling, RollingSunday> || std::is_same_v<Rolling, RollingNone>;
  template <class Rolling>
  static constexpr bool with_rolling = std::is_same_v<Rolling, RollingSunday>;
  static constexpr int kSize = 64;  ///< contacts per batch (about 30 KB: stays in L1)
  int count = 0;
  // Where to scatter.
  std::uint32_t k[kSize], i[kSize], j[kSize];
  // Inputs: centre offset j - i, radii, masses (+inf: fixed; compute() forms m* from them, a
  // division per lane vectorised), velocities (v2 - v1), spins.
  alignas(64) double dx[kSize], dy[kSize], dz[kSize], dist2[kSize];
  alignas(64) double r1[kSize], r2[kSize], m1[kSize], m2[kSize], m_eff[kSize];
  alignas(64) double dvx[kSize], dvy[kSize], dvz[kSize];
  alignas(64) double w1x[kSize], w1y[kSize], w1z[kSize], w2x[kSize], w2y[kSize], w2z[kSize];
  // Pair coefficients: where each lane's are (fill), then copied into the lanes by compute()
  // (load_coefficients).
  const PairCoefficients* coefficients[kSize];
  alignas(64) double E[kSize], G[kSize], damp_n[kSize], damp_t[kSize], mu_s[kSize], mu_r[kSize], mu_t[kSize];
  // History in (fresh contacts come with shear 0, duration 0 and their gate) and out.
  alignas(64) double sx[kSize], sy[kSize], sz[kSize], duration[kSize], gate[kSize];
  alignas(64) double fresh[kSize];  ///< 1: the contact starts this step
  // Outputs: force on body 2 (body 1 gets the opposite), torques, overlap and R* (energy).
  alignas(64) double fx[kSize], fy[kSize], fz[kSize];
  alignas(64) double t1x[kSize], t1y[kSize], t1z[kSize], t2x[kSize], t2y[kSize], t2z[kSize];
  alignas(64) double overlap[kSize], R_eff[kSize];

  [[nodiscard]] bool full() const { return count == kSize; }

  /// Writes lane `count` (not yet kept): list slot kk, particles ii < jj, centre offset
  /// d = x_j - x_i (m) and |d|^2. The pair filter writes every listed pair here and advances
  /// `count` only for a touching one; fill() completes a kept lane.
  GRAVSWEEP_INLINE void put(std::uint32_t kk, std::uint32_t ii, std::uint32_t jj, const Vec3& d, double d2) {
    const int b = count;
    k[b] = kk;
    i[b] = ii;
    j[b] = jj;
    dx[b] = d.x();
    dy[b] = d.y();
    dz[b] = d.z();
    dist2[b] = d2;
  }

  /// Moves what put() wrote from lane `from` to lane `to` (a dropped lane's place).
  GRAVSWEEP_INLINE void move_lane(int from, int to) {
    k[to] = k[from];
    i[to] = i[from];
    j[to] = j[from];
    dx[to] = dx[from];
    dy[to] = dy[from];
    dz[to] = dz[from];
    dist2[to] = dist2[from];
  }

  /// Completes lane b after put(): radii, masses (kg, +inf for a fixed body), velocities, spins,
  /// the pair's coefficients and its history h (a new contact when !h.active).
  GRAVSWEEP_INLINE void fill(int b, double ri, double rj, double mi, double mj, const Vec3& vi, const Vec3& vj,
                             const Vec3& wi, const Vec3& wj, const PairCoefficients& pc, const ContactHistory& h) {
    r1[b] = ri;
    r2[b] = rj;
    m1[b] = mi;
    m2[b] = mj;
    dvx[b] = vj.x() - vi.x();
    dvy[b] = vj.y() - vi.y();
    dvz[b] = vj.z() - vi.z();
    w1x[b] = wi.x();
    w1y[b] = wi.y();
    w1z[b] = wi.z();
    w2x[b] = wj.x();
    w2y[b] = wj.y();
    w2z[b] = wj.z();
    coefficients[b] = &pc;
    if (h.active) {
      sx[b] = h.shear_m.x();
      sy[b] = h.shear_m.y();
      sz[b] = h.shear_m.z();
      duration[b] = h.duration_s;
      gate[b] = h.gate_s;
      fresh[b] = 0;
    } else {
      sx[b] = sy[b] = sz[b] = 0;
      duration[b] = 0;
      gate[b] =
          HertzChrono::gate_s(pc.E_eff_Pa, pc.damping_prefactor_n, ri * rj / (ri + rj), effective_mass_kg(mi, mj));
      fresh[b] = 1;
    }
  }

  /// Appends one touching pair whole (put, fill) with its effective mass meff: h is its history.
  GRAVSWEEP_INLINE void add(std::uint32_t kk, std::uint32_t ii, std::uint32_t jj, const Vec3& d, double d2, double ri,
                            double rj, double meff, const Vec3& vi, const Vec3& vj, const Vec3& wi, const Vec3& wj,
                            const PairCoefficients& pc, const ContactHistory& h) {
    put(kk, ii, jj, d, d2);
    fill(count++, ri, rj, meff, kInf, vi, vj, wi, wj, pc, h);
  }

  /// Evaluates the batch: HertzChrono::evaluate, then (kRolling) RollingSunday::apply.
  template <bool kRolling>
  void compute(const ContactOptions& opt, double dt_s);

 private:
  /// Copies each lane's pair coefficients into E ... mu_t: one value broadcast when every lane
  /// has the same pair of materials (a bed of one material), else lane by lane.
  void load_coefficients();
  struct Lever;
  struct Spins;
  struct Torques;
  /// RollingSunday::apply (docs/physics/contact-laws.md section 1.5) for contact b with normal
  /// force Fn, on once the contact is older than its gate: added to the torques q.
  GRAVSWEEP_INLINE void add_sunday(int b, bool on, double Fn, const Lever& L, const Spins& w, double min_roll,
                                   double min_spin, Torques q) const;
};

/// The contact's normal n (from body 1 to 2), radii and centre distance, for add_sunday.
struct HertzBatch::Lever {
  double nx, ny, nz, ra, rb, dist;
};
/// The spins of bodies 1 (a) and 2 (b), rad/s.
struct HertzBatch::Spins {
  double ax, ay, az, bx, by, bz;
};
/// The torques on bodies 1 and 2 being summed, N m (references to compute()'s lane values).
struct HertzBatch::Torques {
  double &q1x, &q1y, &q1z, &q2x, &q2y, &q2z;
};

inline void HertzBatch::add_sunday(int b, bool on, double Fn, const Lever& L, const Spins& w, double min_roll,
                                   double min_spin, Torques q) const {
  constexpr double kTiny2 = kTinyLength_m * kTinyLength_m;
  const double nx = L.nx, ny = L.ny, nz = L.nz, ra = L.ra, rb = L.rb;
  // v_rot = -(R1 w1 + R2 w2) x n; both bodies get mu_r F_n R_k along n x v_rot / |v_rot|.
  const double Rwx = ra * w.ax + rb * w.bx, Rwy = ra * w.ay + rb * w.by, Rwz = ra * w.az + rb * w.bz;
  const double vox = -(Rwy * nz - Rwz * ny), voy = -(Rwz * nx - Rwx * nz), voz = -(Rwx * ny - Rwy * nx);
  const double vr = std::sqrt(vox * vox + voy * voy + voz * voz);
  const bool roll = on & (mu_r[b] > 0) & (vr > min_roll);
  const double inv_vr = 1.0 / vr;
  const double ux = vox * inv_vr, uy = voy * inv_vr, uz = voz * inv_vr;
  const double dirx = ny * uz - nz * uy, diry = nz * ux - nx * uz, dirz = nx * uy - ny * ux;
  const double mr = mu_r[b] * Fn;
  const double c1 = mr * ra, c2 = mr * rb;
  q.q1x = roll ? q.q1x + c1 * dirx : q.q1x;
  q.q1y = roll ? q.q1y + c1 * diry : q.q1y;
  q.q1z = roll ? q.q1z + c1 * dirz : q.q1z;
  q.q2x = roll ? q.q2x + c2 * dirx : q.q2x;
  q.q2y = roll ? q.q2y + c2 * diry : q.q2y;
  q.q2z = roll ? q.q2z + c2 * dirz : q.q2z;
  // Spinning: mu_t r_c F_n along n, r_c the radius of the contact lens.
  const double wrx = w.bx - w.ax, wry = w.by - w.ay, wrz = w.bz - w.az;
  const double wr = std::sqrt(wrx * wrx + wry * wry + wrz * wrz);
  const bool spin = on & (mu_t[b] > 0) & (wr > min_spin);
  const double dcc = L.dist;
  const double xc = (ra * ra - rb * rb) / (2 * dcc) + dcc / 2;
  const double rc = std::sqrt(std::max(ra * ra - xc * xc, kTiny2));
  const double wn = (wrx * nx + wry * ny + wrz * nz) / wr;
  const double Mm = mu_t[b] * rc * Fn * wn;
  const double Mx = Mm * nx, My = Mm * ny, Mz = Mm * nz;
  q.q1x = spin ? q.q1x + Mx : q.q1x;
  q.q1y = spin ? q.q1y + My : q.q1y;
  q.q1z = spin ? q.q1z + Mz : q.q1z;
  q.q2x = spin ? q.q2x - Mx : q.q2x;
  q.q2y = spin ? q.q2y - My : q.q2y;
  q.q2z = spin ? q.q2z - Mz : q.q2z;
}

inline void HertzBatch::load_coefficients() {
  const int nb = count;
  bool uniform = true;
  for (int b = 1; b < nb; ++b) uniform &= coefficients[b] == coefficients[0];
  if (uniform && nb > 0) {
    const PairCoefficients& pc = *coefficients[0];
    std::fill_n(E, nb, pc.E_eff_Pa);
    std::fill_n(G, nb, pc.G_eff_Pa);
    std::fill_n(damp_n, nb, pc.damping_prefactor_n);
    std::fill_n(damp_t, nb, pc.damping_prefactor_t);
    std::fill_n(mu_s, nb, pc.mu_static);
    std::fill_n(mu_r, nb, pc.mu_rolling);
    std::fill_n(mu_t, nb, pc.mu_twisting);
    return;
  }
  for (int b = 0; b < nb; ++b) {
    const PairCoefficients& pc = *coefficients[b];
    E[b] = pc.E_eff_Pa;
    G[b] = pc.G_eff_Pa;
    damp_n[b] = pc.damping_prefactor_n;
    damp_t[b] = pc.damping_prefactor_t;
    mu_s[b] = pc.mu_static;
    mu_r[b] = pc.mu_rolling;
    mu_t[b] = pc.mu_twisting;
  }
}

template <bool kRolling>
void HertzBatch::compute(const ContactOptions& opt, double dt_s) {
  load_coefficients();
  const int nb = count;
  // m* in a loop of its own: inlined into the contact's expressions below, GCC's vectorised m*
  // moved the 1 g drop's trace from the per-pair value's (not bit for bit).
#pragma omp simd
  for (int b = 0; b < nb; ++b) m_eff[b] = effective_mass_kg(m1[b], m2[b]);
  const bool clamp = opt.clamp_normal;
  const double min_roll = opt.min_roll_vel_m_s, min_spin = opt.min_spin_vel_rad_s;
  constexpr double kTiny2 = kTinyLength_m * kTinyLength_m;
#pragma omp simd
  for (int b = 0; b < nb; ++b) {
    const double dist = std::sqrt(dist2[b]);
    const double inv_dist = 1.0 / dist;
    const double nx = dx[b] * inv_dist, ny = dy[b] * inv_dist, nz = dz[b] * inv_dist;
    const double ra = r1[b], rb = r2[b];
    const double rsum = ra + rb;
    const double delta = rsum - dist;
    const double Reff = ra * rb / rsum;
    const double m = m_eff[b];
    // Contact-point levers s1 = r1 n, s2 = -r2 n; v_rel = (v2 + w2 x s2) - (v1 + w1 x s1).
    const double s1x = ra * nx, s1y = ra * ny, s1z = ra * nz;
    const double s2x = -rb * nx, s2y = -rb * ny, s2z = -rb * nz;
    const double ax = w1x[b], ay = w1y[b], az = w1z[b];
    const double bx = w2x[b], by = w2y[b], bz = w2z[b];
    const double vrx = dvx[b] + (by * s2z - bz * s2y) - (ay * s1z - az * s1y);
    const double vry = dvy[b] + (bz * s2x - bx * s2z) - (az * s1x - ax * s1z);
    const double vrz = dvz[b] + (bx * s2y - by * s2x) - (ax * s1y - ay * s1x);
    const double v_n = vrx * nx + vry * ny + vrz * nz;
    const double vtx = vrx - v_n * nx, vty = vry - v_n * ny, vtz = vrz - v_n * nz;
    // Stiffness and damping (docs/physics/contact-laws.md section 1.3).
    const auto [kn, kt, gn, gt] = HertzChrono::springs(E[b], G[b], damp_n[b], damp_t[b], Reff, delta, m);
    double Fn = kn * delta - gn * v_n;
    Fn = (clamp & (Fn < 0)) ? 0.0 : Fn;
    // MultiStep history (1.4).
    const double older = duration[b] + dt_s;
    const double dur = fresh[b] != 0 ? 0.0 : older;
    double hx = sx[b] + vtx * dt_s, hy = sy[b] + vty * dt_s, hz = sz[b] + vtz * dt_s;
    const double hn = hx * nx + hy * ny + hz * nz;
    hx -= hn * nx;
    hy -= hn * ny;
    hz -= hn * nz;
    double Ftx = kt * hx + gt * vtx, Fty = kt * hy + gt * vty, Ftz = kt * hz + gt * vtz;
    const double Ft_max = mu_s[b] * std::abs(Fn);
    const double Ft_mag = std::sqrt(Ftx * Ftx + Fty * Fty + Ftz * Ftz);
    const bool slip = Ft_mag > Ft_max;
    const bool spring = hx * hx + hy * hy + hz * hz > kTiny2;
    const double limit_scale = Ft_max / Ft_mag;
    const double scale = slip ? (spring ? limit_scale : 0.0) : 1.0;
    Ftx *= scale;
    Fty *= scale;
    Ftz *= scale;
    const double inv_kt = 1.0 / kt;
    const bool back_solve = slip & spring;  // the spring at the Coulomb limit
    const double bsx = (Ftx - gt * vtx) * inv_kt, bsy = (Fty - gt * vty) * inv_kt, bsz = (Ftz - gt * vtz) * inv_kt;
    hx = back_solve ? bsx : hx;
    hy = back_solve ? bsy : hy;
    hz = back_solve ? bsz : hz;
    const double f2x = Fn * nx - Ftx, f2y = Fn * ny - Fty, f2z = Fn * nz - Ftz;
    // torque_1 = s1 x (-f2), torque_2 = s2 x f2.
    double q1x = -(s1y * f2z - s1z * f2y), q1y = -(s1z * f2x - s1x * f2z), q1z = -(s1x * f2y - s1y * f2x);
    double q2x = s2y * f2z - s2z * f2y, q2y = s2z * f2x - s2x * f2z, q2z = s2x * f2y - s2y * f2x;
    if constexpr (kRolling)
      add_sunday(b, dur > gate[b], Fn, Lever{nx, ny, nz, ra, rb, rsum - delta}, Spins{ax, ay, az, bx, by, bz}, min_roll,
                 min_spin, Torques{q1x, q1y, q1z, q2x, q2y, q2z});
    fx[b] = f2x;
    fy[b] = f2y;
    fz[b] = f2z;
    t1x[b] = q1x;
    t1y[b] = q1y;
    t1z[b] = q1z;
    t2x[b] = q2x;
    t2y[b] = q2y;
    t2z[b] = q2z;
    sx[b] = hx;
    sy[b] = hy;
    sz[b] = hz;
    duration[b] = dur;
    overlap[b] = delta;
    R_eff[b] = Reff;
  }
}

}  // namespace gravsweep

// `sunday`: Chrono/Sunday et al. 2020 constant-magnitude rolling and spinning torques
// (Schwartz et al. 2012 style), exactly as docs/physics/contact-laws.md section 1.5. Direction from
// the relative rotation; off below the speed thresholds and during the first t_collision of a
// contact.
#pragma once
#include <algorithm>
#include <cmath>

#include "engine/contact/contact.h"

namespace gravsweep {

struct RollingSunday {
  static constexpr const char* name = "sunday";
  static constexpr const char* description =
      "Chrono/Sunday 2020 constant-magnitude rolling (mu_r F_n R) and spinning (mu_t r_c F_n) "
      "torques with activation gate and 1e-4 speed thresholds";
  /// Needs FrameHistory stored per contact (contact.h).
  static constexpr bool uses_frame_history = false;

  GRAVSWEEP_INLINE static void apply(const ContactGeometry& g, const PairCoefficients& c, const ContactOptions& opt,
                                     ContactHistory& h, FrameHistory& /*fh*/, double /*dt_s*/, ContactForce& out) {
    if (h.duration_s <= h.gate_s) return;  // activation gate: mu_r = mu_t = 0 early in a contact
    const Vec3& n = g.n;
    const double Fn = out.normal_force_N;  // signed damped normal force
    if (c.mu_rolling > 0) {
      // Rotational part of the sliding velocity: v_rot = -(R1 w1 + R2 w2) x n.
      const Vec3 Rw = g.wall ? Vec3(g.r1_m * g.w1) : Vec3(g.r1_m * g.w1 + g.r2_m * g.w2);
      const Vec3 v_rot = -Rw.cross(n);
      const double vr = v_rot.norm();
      if (vr > opt.min_roll_vel_m_s) {
        const Vec3 dir = n.cross(v_rot / vr);
        // Both bodies receive torque in the same direction, each with its own radius.
        out.torque_1 += c.mu_rolling * Fn * g.r1_m * dir;
        if (!g.wall) out.torque_2 += c.mu_rolling * Fn * g.r2_m * dir;
      }
    }
    if (c.mu_twisting > 0) {
      const Vec3 w_rel = g.wall ? Vec3(-g.w1) : Vec3(g.w2 - g.w1);
      const double wr = w_rel.norm();
      if (wr > opt.min_spin_vel_rad_s) {
        const double delta = g.overlap_m;
        double rc2;
        if (g.wall) {
          rc2 = 2 * g.r1_m * delta - delta * delta;  // plane limit of the lens radius
        } else {
          const double r1 = g.r1_m, r2 = g.r2_m, dcc = r1 + r2 - delta;
          const double xc = (r1 * r1 - r2 * r2) / (2 * dcc) + dcc / 2;
          rc2 = r1 * r1 - xc * xc;
        }
        const double rc = std::sqrt(std::max(rc2, kTinyLength_m * kTinyLength_m));
        const Vec3 M = c.mu_twisting * rc * Fn * (w_rel.dot(n) / wr) * n;
        out.torque_1 += M;
        if (!g.wall) out.torque_2 -= M;
      }
    }
  }
};

}  // namespace gravsweep

// `zhang`: pkdgrav / Zhang et al. 2017 rolling and twisting spring-dashpot-sliders with shape
// parameter beta, exactly as docs/physics/contact-laws.md section 2.3. The springs rotate with the
// contact frame and the step's increment is undone when a slider slips.
#pragma once
#include <cmath>

#include "engine/contact/contact.h"

namespace gravsweep {

struct RollingZhang {
  static constexpr const char* name = "zhang";
  static constexpr const char* description =
      "pkdgrav/Zhang 2017 rolling and twisting spring-dashpot-sliders, k_R = kN (beta Rbar)^2, "
      "M_R <= mu_r beta Rbar |F_N|, M_Q <= mu_t mu_s beta Rbar |F_N|";
  /// Needs FrameHistory stored per contact (contact.h).
  static constexpr bool uses_frame_history = true;

  GRAVSWEEP_INLINE static void apply(const ContactGeometry& g, const PairCoefficients& c, const ContactOptions&,
                                     ContactHistory& /*h*/, FrameHistory& fh, double dt_s, ContactForce& out) {
    const Vec3& n = g.n;
    const double Rbar = g.wall ? g.r1_m : g.r1_m * g.r2_m / (g.r1_m + g.r2_m);
    const double bR2 = (c.shape_beta * Rbar) * (c.shape_beta * Rbar);
    const double kR = out.kn_N_m * bR2, CR = out.cn_N_s_m * bR2;
    const double kQ = 2 * out.kt_N_m * bR2, CQ = 2 * out.ct_N_s_m * bR2;
    const double FN = std::abs(out.normal_force_N);

    const Vec3 w_rel = g.wall ? Vec3(-g.w1) : Vec3(g.w2 - g.w1);
    const double w_twist = w_rel.dot(n);
    const double l1 = out.lever1_m, l2 = out.lever2_m;
    const double curvature = g.wall ? 1.0 / l1 : (l2 - l1) / (l1 * l2);
    const Vec3 w_roll = w_rel - w_twist * n + 0.5 * curvature * n.cross(out.u_contact);

    // Rolling spring, rotated with the frame and kept in the tangent plane.
    Vec3 phi_old = out.frame_rotation * fh.roll_rad;
    phi_old -= phi_old.dot(n) * n;
    fh.roll_rad = phi_old + w_roll * dt_s;
    const double MR_max = c.mu_rolling * c.shape_beta * Rbar * FN;
    Vec3 MR = kR * fh.roll_rad + CR * w_roll;
    const double spring_R = kR * fh.roll_rad.norm();
    if (spring_R > MR_max) {
      MR = spring_R > 0 ? Vec3(MR_max * fh.roll_rad.normalized()) : Vec3::Zero();
      fh.roll_rad = phi_old;  // undo this step's increment
    }
    // Twisting spring.
    const double phiQ_old = fh.twist_rad;
    fh.twist_rad += w_twist * dt_s;
    const double MQ_max = c.mu_twisting * c.mu_static * c.shape_beta * Rbar * FN;
    double MQ = kQ * fh.twist_rad + CQ * w_twist;
    if (std::abs(kQ * fh.twist_rad) > MQ_max) {
      MQ = (fh.twist_rad > 0 ? 1.0 : -1.0) * MQ_max;
      fh.twist_rad = phiQ_old;
    }
    out.torque_1 += MR + MQ * n;
    if (!g.wall) out.torque_2 -= MR + MQ * n;
  }
};

}  // namespace gravsweep

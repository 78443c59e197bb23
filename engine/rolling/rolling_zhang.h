// `zhang`: pkdgrav / Zhang et al. 2017 rolling and twisting spring-dashpot-sliders with shape
// parameter beta, exactly as docs/physics/contact-laws.md section 2.3. The springs rotate with the
// contact frame and the step's increment is undone when a slider slips.
#pragma once
#include <algorithm>
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

  /// The spring a slider keeps when this step's increment is undone: the spring of the step
  /// before, or, when that spring is itself beyond the limit (the limit falls with |F_N| while
  /// the spring is loaded), the spring scaled down to the limit. Undoing the increment alone
  /// would keep a stale spring beyond the limit: the slider would then push at the limit in the
  /// direction of a motion that never unloads it, doing positive work every step (in a bed at
  /// 1 g it kept floor grains spinning about the floor's normal at 5-50 rad/s and the bed from
  /// coming to rest; docs/physics/contact-laws.md section 2.3).
  GRAVSWEEP_INLINE static double held_at_limit(double phi_rad, double k_N_m_rad, double limit_N_m) {
    const double held = limit_angle_rad(k_N_m_rad, limit_N_m);
    return std::clamp(phi_rad, -held, held);
  }
  GRAVSWEEP_INLINE static Vec3 held_at_limit(const Vec3& phi_rad, double k_N_m_rad, double limit_N_m) {
    const double held = limit_angle_rad(k_N_m_rad, limit_N_m), size = phi_rad.norm();
    return size > held ? Vec3(phi_rad * (held / size)) : phi_rad;
  }
  /// The angle at which a spring of stiffness k reaches the torque limit (0 without a spring).
  GRAVSWEEP_INLINE static double limit_angle_rad(double k_N_m_rad, double limit_N_m) {
    return k_N_m_rad > 0 ? limit_N_m / k_N_m_rad : 0;
  }

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
      fh.roll_rad = held_at_limit(phi_old, kR, MR_max);  // undo this step's increment
    }
    // Twisting spring.
    const double phiQ_old = fh.twist_rad;
    fh.twist_rad += w_twist * dt_s;
    const double MQ_max = c.mu_twisting * c.mu_static * c.shape_beta * Rbar * FN;
    double MQ = kQ * fh.twist_rad + CQ * w_twist;
    if (std::abs(kQ * fh.twist_rad) > MQ_max) {
      MQ = (fh.twist_rad > 0 ? 1.0 : -1.0) * MQ_max;
      fh.twist_rad = held_at_limit(phiQ_old, kQ, MQ_max);  // undo this step's increment
    }
    out.torque_1 += MR + MQ * n;
    if (!g.wall) out.torque_2 -= MR + MQ * n;
  }
};

}  // namespace gravsweep

// `hooke`: pkdgrav SSDEM linear spring-dashpot (Schwartz et al. 2012), exactly as
// docs/physics/contact-laws.md sections 2.1-2.2 (pkdgrav smoothfcn.c DoDEM): damping from the
// normal and tangential restitution, tangential spring rotated with the contact frame and reset to
// zero on slip.
#pragma once
#include <fmt/format.h>

#include <cmath>
#include <string>

#include "engine/contact/contact.h"
#include "engine/core/error.h"

namespace gravsweep {

struct HookePkdgrav {
  static constexpr const char* name = "hooke";
  static constexpr const char* description =
      "pkdgrav SSDEM linear spring-dashpot (kN, kT = 2/7 kN by default, damping from eps_n and "
      "eps_t), tangential spring rotated with the contact frame, reset on slip";
  /// Needs FrameHistory stored per contact (contact.h).
  static constexpr bool uses_frame_history = true;

  /// C = 2 |ln e| sqrt(k mu / (pi^2 + ln^2 e)) = prefactor * sqrt(k mu)
  /// (docs/physics/contact-laws.md section 2.1).
  static double damping_prefactor(double cor) {
    const double loge = std::log(cor);
    return 2.0 * std::abs(loge) / std::sqrt(kPi * kPi + loge * loge);
  }

  /// Caches the damping prefactors; C = prefactor * sqrt(k mu). eps_t = 1 gives C_T = 0.
  static void prepare(PairCoefficients& c) {
    c.damping_prefactor_n = damping_prefactor(c.cor_normal);
    c.damping_prefactor_t = c.cor_tangential >= 1.0 ? 0.0 : damping_prefactor(c.cor_tangential);
  }

  /// Normal spring energy U = kN x^2 / 2, evaluated only when energy is tracked.
  static double normal_energy_J(const ContactGeometry& g, const PairCoefficients& c) {
    return 0.5 * c.kn_N_m * g.overlap_m * g.overlap_m;
  }

  /// Linear-contact duration t_c = pi sqrt(mu/k) sqrt(1 + ln^2 e / pi^2)
  /// (docs/physics/contact-laws.md section 2.4).
  static double contact_time_s(double k_N_m, double m_eff_kg, double cor) {
    const double loge = std::log(cor);
    return kPi * std::sqrt(m_eff_kg / k_N_m) * std::sqrt(1 + loge * loge / (kPi * kPi));
  }

  /// Shortest contact time of the pairs present; a linear spring's does not depend on the speed.
  static double shortest_contact_time_s(const LawSetup& s, double /*v_rel_m_s*/) {
    double t = kInf;
    for_each_smallest_pair(s, [&](const SmallestPair& p) {
      const PairCoefficients& c = s.pairs(p.a, p.b);
      if (c.kn_N_m > 0) t = std::min(t, contact_time_s(c.kn_N_m, p.m_eff_kg, c.cor_normal));
    });
    return t;
  }

  /// Largest stable step: every pair contact must last at least kMinStepsPerContact steps.
  static constexpr double kMinStepsPerContact = 10.0;
  static void check(const LawSetup& s) {
    for_each_smallest_pair(s, [&](const SmallestPair& p) {
      const PairCoefficients& c = s.pairs(p.a, p.b);
      const std::string label = s.materials[p.a].name + "-" + s.materials[p.b].name;
      if (!(c.kn_N_m > 0))
        throw ConfigError(fmt::format("contact law 'hooke': kn_N_m = {} for pair {}; expected a spring constant > 0",
                                      c.kn_N_m, label));
      if (!s.check_time_step) return;
      const double limit = contact_time_s(c.kn_N_m, p.m_eff_kg, c.cor_normal) / kMinStepsPerContact;
      if (s.dt_s > limit)
        throw ConfigError(
            fmt::format("contact law 'hooke': dt = {:.3g} s exceeds the stability bound {:.3g} s "
                        "(contact time / {} for pair {})",
                        s.dt_s, limit, kMinStepsPerContact, label));
    });
  }

  GRAVSWEEP_INLINE static void evaluate(const ContactGeometry& g, const PairCoefficients& c,
                                        const ContactOptions& /*opt*/, ContactHistory& h, FrameHistory& fh, double dt_s,
                                        ContactForce& out) {
    const Vec3& n = g.n;
    // Lever arms to the contact plane (2.1); a wall is a sphere of infinite radius.
    double l1, l2;
    if (g.wall) {
      l1 = g.distance_m;
      l2 = kInf;
    } else {
      const double d = g.distance_m;
      l1 = (g.r1_m * g.r1_m - g.r2_m * g.r2_m + d * d) / (2 * d);
      l2 = d - l1;
    }
    Vec3 u = -g.v1 - l1 * g.w1.cross(n);
    if (!g.wall) u += g.v2 - l2 * g.w2.cross(n);
    const double u_n = u.dot(n);
    const Vec3 u_T = u - u_n * n;

    const double cN = c.damping_prefactor_n * std::sqrt(c.kn_N_m * g.m_eff_kg);
    const double cT = c.damping_prefactor_t * std::sqrt(c.kt_N_m * g.m_eff_kg);
    // Force on body 1: F_N = -kN x n + C_N u_N (no tensile clamp).
    const Vec3 FN1 = -c.kn_N_m * g.overlap_m * n + cN * u_n * n;

    // Frame rotation of the tangential spring (2.2): rigid twist about n_bar, then n_old -> n.
    Quat rot = Quat::Identity();
    if (!h.active) {
      h = ContactHistory{};
      h.active = true;
      fh.n_old = n;
    } else {
      h.duration_s += dt_s;
      const Vec3 nbar_raw = fh.n_old + n;
      const double nb = nbar_raw.norm();
      if (nb > 0) {
        const Vec3 nbar = nbar_raw / nb;
        const Vec3 w_sum = g.wall ? g.w1 : Vec3(g.w1 + g.w2);
        const double angle = 0.5 * dt_s * w_sum.dot(nbar);
        const Quat twist(Eigen::AngleAxisd(angle, nbar));
        const Quat tilt = Quat::FromTwoVectors(fh.n_old, n);
        rot = tilt * twist;
        h.shear_m = rot * h.shear_m;
      }
      fh.n_old = n;
    }
    h.shear_m += u_T * dt_s;
    Vec3 FT1 = c.kt_N_m * h.shear_m + cT * u_T;
    const double FN_mag = FN1.norm();
    if (FT1.squaredNorm() > c.mu_static * c.mu_static * FN_mag * FN_mag) {
      // Saw-tooth slip: reset the spring; the force is the smaller of Coulomb and the dashpot.
      h.shear_m.setZero();
      const double ut = u_T.norm();
      FT1 = ut > 0 ? Vec3(std::min(c.mu_static * FN_mag, cT * ut) * (u_T / ut)) : Vec3::Zero();
    }

    out.force_on_2 = -(FN1 + FT1);
    out.torque_1 = l1 * n.cross(FT1);
    out.torque_2 = g.wall ? Vec3::Zero() : Vec3(l2 * n.cross(FT1));
    out.normal_force_N = c.kn_N_m * g.overlap_m - cN * u_n;
    out.kn_N_m = c.kn_N_m;
    out.kt_N_m = c.kt_N_m;
    out.cn_N_s_m = cN;
    out.ct_N_s_m = cT;
    out.u_contact = u;
    out.lever1_m = l1;
    out.lever2_m = l2;
    out.frame_rotation = rot;
  }
};

}  // namespace gravsweep

// `hertz`: Chrono::Multicore SMC, Hertz law on the material-property path, MultiStep tangential
// history. Exactly as docs/physics/contact-laws.md sections 1.3-1.5
// (Chrono ChIterativeSolverMulticoreSMC.cpp).
#pragma once
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/contact/contact.h"
#include "engine/core/error.h"

namespace gravsweep {

struct HertzBatch;  // engine/system/hertz_batch.h

struct HertzChrono {
  static constexpr const char* name = "hertz";
  static constexpr const char* description =
      "Chrono::Multicore SMC Hertz law (E, nu, COR -> kn, kt, gn, gt), MultiStep tangential "
      "history projected onto the tangent plane with Coulomb back-solve";
  /// Needs FrameHistory stored per contact (contact.h).
  static constexpr bool uses_frame_history = false;
  /// The particle-particle contacts evaluated a batch at a time (optional in a law: the force loop
  /// uses Batch when the law names one and Batch::supports the rolling model, kHasBatch).
  using Batch = HertzBatch;

  /// Chrono's damping factor -2 sqrt(5/6) beta with beta = ln e / sqrt(ln^2 e + pi^2) >= 0.
  static double damping_factor(double cor) {
    const double loge = std::log(std::max(cor, std::numeric_limits<double>::epsilon()));
    const double beta = loge / std::sqrt(loge * loge + kPi * kPi);
    return -2.0 * std::sqrt(5.0 / 6.0) * beta;
  }

  /// Stiffness and damping at overlap delta (docs/physics/contact-laws.md section 1.3):
  /// Sn = 2 E* sqrt(R* delta), kn = 2/3 Sn, kt = St = 8 G* sqrt(R* delta), gn = f_n sqrt(Sn m*),
  /// gt = f_t sqrt(Sn m*) with the damping factors of prepare(). Evaluate and the batched kernel
  /// (HertzBatch) both call it.
  struct Springs {
    double kn_N_m, kt_N_m, gn_N_s_m, gt_N_s_m;
  };
  GRAVSWEEP_INLINE static Springs springs(double E_eff_Pa, double G_eff_Pa, double damping_n, double damping_t,
                                          double R_eff_m, double delta_m, double m_eff_kg) {
    const double sqrt_Rd = std::sqrt(R_eff_m * delta_m);
    const double Sn = 2.0 * E_eff_Pa * sqrt_Rd;
    const double sqrt_Sn_m = std::sqrt(Sn * m_eff_kg);
    return {(2.0 / 3.0) * Sn, 8.0 * G_eff_Pa * sqrt_Rd, damping_n * sqrt_Sn_m, damping_t * sqrt_Sn_m};
  }

  /// Caches the damping factors of the pair. Chrono uses the normal COR for both directions:
  /// gn = f sqrt(Sn m*), gt = f sqrt(St m*) = [f sqrt(4 G*/E*)] sqrt(Sn m*) since St/Sn = 4 G*/E*.
  static void prepare(PairCoefficients& c) {
    c.damping_prefactor_n = damping_factor(c.cor_normal);
    c.damping_prefactor_t = c.damping_prefactor_n * std::sqrt(4.0 * c.G_eff_Pa / c.E_eff_Pa);
  }

  /// Normal spring energy U = integral of (4/3) E* sqrt(R*) d^1.5 = (8/15) E* sqrt(R*) d^2.5,
  /// evaluated only when energy is tracked.
  static double normal_energy_J(const ContactGeometry& g, const PairCoefficients& c) {
    return normal_energy_J(c.E_eff_Pa, g.R_eff_m, g.overlap_m);
  }
  /// The same from E*, R* and the overlap d (the batched kernel's energy).
  GRAVSWEEP_INLINE static double normal_energy_J(double E_eff_Pa, double R_eff_m, double d_m) {
    return (8.0 / 15.0) * E_eff_Pa * std::sqrt(R_eff_m) * d_m * d_m * std::sqrt(d_m);
  }

  /// The rolling and spinning activation gate t_collision of a new contact (section 1.5): the
  /// half period of the damped oscillator with the delta-free Hertz constants
  /// kn_s = 4/3 E* sqrt(R*), gn_s = f_n sqrt(2 E* sqrt(R*) m*); 0 when overdamped.
  static double gate_s(double E_eff_Pa, double damping_n, double R_eff_m, double m_eff_kg) {
    const double kn_s = (4.0 / 3.0) * E_eff_Pa * std::sqrt(R_eff_m);
    const double gn_s = damping_n * std::sqrt(2.0 * E_eff_Pa * std::sqrt(R_eff_m) * m_eff_kg);
    const double d = gn_s / (2.0 * m_eff_kg * std::sqrt(kn_s / m_eff_kg));
    return d < 1 ? kPi * std::sqrt(m_eff_kg / (kn_s * (1 - d * d))) : 0.0;
  }

  /// Rayleigh time T_R = pi R sqrt(rho/G) / (0.1631 nu + 0.8766), G = E / (2(1+nu))
  /// (docs/physics/contact-laws.md section 3.1).
  static double rayleigh_time_s(const Material& m, double radius_m) {
    const double G = m.young_modulus_Pa / (2 * (1 + m.poisson_ratio));
    return kPi * radius_m * std::sqrt(m.density_kg_m3 / G) / (0.1631 * m.poisson_ratio + 0.8766);
  }

  /// Shortest elastic contact time of the pairs present at relative normal speed v_rel_m_s:
  /// t_H = 2.868 (m*^2 / (R* E*^2 v))^(1/5)
  /// (Johnson 1985; docs/physics/contact-laws.md section 4.1), from each particle material's
  /// smallest radius and mass (a wall: infinite mass and radius). t_H grows as v^(-1/5): 2.6 times
  /// longer at 0.01 m/s than at 1.2 m/s. Infinite for v_rel_m_s <= 0.
  static double shortest_contact_time_s(const LawSetup& s, double v_rel_m_s) {
    double t = kInf;
    if (!(v_rel_m_s > 0)) return t;
    for_each_smallest_pair(s, [&](const SmallestPair& p) {
      const double E = s.pairs(p.a, p.b).E_eff_Pa;
      t = std::min(t,
                   kHertzContactTimeFactor * std::pow(p.m_eff_kg * p.m_eff_kg / (p.r_eff_m * E * E * v_rel_m_s), 0.2));
    });
    return t;
  }
  static constexpr double kHertzContactTimeFactor = 2.868;

  /// Largest stable step: a fraction of the Rayleigh time of the smallest particle of each
  /// particle material.
  static constexpr double kMaxDtOverRayleigh = 0.3;
  static void check(const LawSetup& s) {
    for (std::size_t m = 0; m < s.materials.size(); ++m) {
      if (s.is_wall_material[m] || s.min_radius_m[m] <= 0 || !s.check_time_step) continue;
      const Material& mat = s.materials[m];
      const double limit = kMaxDtOverRayleigh * rayleigh_time_s(mat, s.min_radius_m[m]);
      if (s.dt_s > limit)
        throw ConfigError(
            fmt::format("contact law 'hertz': dt = {:.3g} s exceeds the stability bound {:.3g} s "
                        "(0.3 x Rayleigh time of material '{}' at radius {:.3g} m)",
                        s.dt_s, limit, mat.name, s.min_radius_m[m]));
    }
  }

  GRAVSWEEP_INLINE static void evaluate(const ContactGeometry& g, const PairCoefficients& c, const ContactOptions& opt,
                                        ContactHistory& h, FrameHistory& /*fh*/, double dt_s, ContactForce& out) {
    const Vec3& n = g.n;
    const double delta = g.overlap_m;
    // Contact points on each surface with full-radius levers (ChNarrowphasePRIMS sphere_sphere).
    const Vec3 s1 = g.r1_m * n;
    const Vec3 vP1 = g.v1 + g.w1.cross(s1);
    Vec3 s2 = Vec3::Zero();
    Vec3 vP2 = Vec3::Zero();
    if (!g.wall) {
      s2 = -g.r2_m * n;
      vP2 = g.v2 + g.w2.cross(s2);
    }
    const Vec3 v_rel = vP2 - vP1;
    const double v_n = v_rel.dot(n);  // negative while approaching
    const Vec3 v_t = v_rel - v_n * n;

    const auto [kn, kt, gn, gt] =
        springs(c.E_eff_Pa, c.G_eff_Pa, c.damping_prefactor_n, c.damping_prefactor_t, g.R_eff_m, delta, g.m_eff_kg);
    double Fn = kn * delta - gn * v_n;  // unclamped, as in Chrono
    if (opt.clamp_normal && Fn < 0) Fn = 0;

    // MultiStep history (1.4): new contact -> zero; else accumulate duration.
    if (!h.active) {
      h = ContactHistory{};
      h.active = true;
      h.gate_s = gate_s(c.E_eff_Pa, c.damping_prefactor_n, g.R_eff_m, g.m_eff_kg);
    } else {
      h.duration_s += dt_s;
    }
    h.shear_m += v_t * dt_s;
    h.shear_m -= h.shear_m.dot(n) * n;  // project onto the current tangent plane, no rescale
    Vec3 Ft = kt * h.shear_m + gt * v_t;
    const double Ft_max = c.mu_static * std::abs(Fn);
    const double Ft_mag = Ft.norm();
    if (Ft_mag > Ft_max) {
      if (h.shear_m.norm() > kTinyLength_m) {
        Ft *= Ft_max / Ft_mag;
        h.shear_m = (Ft - gt * v_t) / kt;  // back-solve the spring at the Coulomb limit
      } else {
        Ft.setZero();
      }
    }

    out.force_on_2 = Fn * n - Ft;
    out.torque_1 = s1.cross(-out.force_on_2);
    out.torque_2 = g.wall ? Vec3::Zero() : Vec3(s2.cross(out.force_on_2));
    out.normal_force_N = Fn;
    out.kn_N_m = kn;
    out.kt_N_m = kt;
    out.cn_N_s_m = gn;
    out.ct_N_s_m = gt;
    out.u_contact = v_rel;
    out.lever1_m = g.r1_m;
    out.lever2_m = g.wall ? kInf : g.r2_m;
    out.frame_rotation = Quat::Identity();
  }
};

}  // namespace gravsweep

// Small set-ups shared by the physics tests: glass beads of Table 1 and a pkdgrav-like Hooke set.
#pragma once
#include <cmath>

#include "engine/scenario/paper_params.h"
#include "engine/system/system.h"

namespace gravsweep::test {

inline constexpr double kBeadRadius_m = 0.005;
inline constexpr double kGlassDensity_kg_m3 = 2480.0;
inline double bead_mass_kg(double r = kBeadRadius_m) { return kGlassDensity_kg_m3 * 4.0 / 3.0 * kPi * r * r * r; }

/// Two materials (0: grain, 1: wall) with the given normal COR for every pair, friction mu.
inline SystemConfig two_material_config(const std::string& law, double cor, double mu,
                                        const std::string& rolling = "none") {
  SystemConfig c = chrono_table1_config(0.0);
  c.contact_law = law;
  c.rolling_model = rolling;
  c.gravity_m_s2 = Vec3::Zero();
  c.threads = 1;
  c.materials.resize(2);
  for (auto& m : c.materials) {
    m.cor_normal = cor;
    m.mu_static = mu;
    m.mu_rolling = 0;
    m.mu_twisting = 0;
    m.kn_N_m = 7.48e5;  // pkdgrav-style k_N for 1 % overlap at 1.2 m/s (docs/physics/contact-laws.md section 2.4)
  }
  c.pair_overrides.clear();
  c.composition = Composition::chrono_min;
  if (law == "hooke") {
    c.integrator = "leapfrog_kdk";
    c.dt_s = 5e-7;
  }
  return c;
}

/// Hertz elastic contact time t_H = 2.868 (m*^2 / (R* E*^2 v))^(1/5)
/// (docs/physics/contact-laws.md section 4.1).
inline double hertz_contact_time_s(double m_eff, double R_eff, double E_eff, double v) {
  return 2.868 * std::pow(m_eff * m_eff / (R_eff * E_eff * E_eff * v), 0.2);
}
/// Hertz elastic peak overlap delta_max = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5).
inline double hertz_peak_overlap_m(double m_eff, double R_eff, double E_eff, double v) {
  return std::pow(15.0 * m_eff * v * v / (16.0 * E_eff * std::sqrt(R_eff)), 0.4);
}

}  // namespace gravsweep::test

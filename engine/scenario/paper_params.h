// Table 1 of Sunday et al. 2021 (A&A 656, A97): the baseline parameter sets of both codes.
#pragma once
#include "engine/system/system.h"

namespace gravsweep {

/// Material ids used by the paper's set-ups.
inline constexpr std::uint8_t kGrainMaterial = 0;
inline constexpr std::uint8_t kWallMaterial = 1;
inline constexpr std::uint8_t kProjectileMaterial = 2;

/// The three materials of the paper's set-ups from the grain's: the wall and the projectile are
/// made of it, the wall with its own normal COR and sliding friction, which explicit pair values
/// for grain-wall and projectile-wall make act (docs/physics/contact-laws.md section 1.2).
inline void set_paper_materials(SystemConfig& c, const Material& grain, double wall_cor_normal, double wall_mu_static) {
  Material wall = grain;
  wall.name = "wall";
  wall.cor_normal = wall_cor_normal;
  wall.mu_static = wall_mu_static;
  Material projectile = grain;
  projectile.name = "projectile";
  c.materials = {grain, wall, projectile};
  c.composition = Composition::explicit_pair;
  PairOverride with_wall;
  with_wall.cor_normal = wall_cor_normal;
  with_wall.mu_static = wall_mu_static;
  c.pair_overrides[{kGrainMaterial, kWallMaterial}] = with_wall;
  c.pair_overrides[{kWallMaterial, kProjectileMaterial}] = with_wall;
}

/// Chrono column of Table 1: Hertz, E = 700 MPa, nu = 0.24, COR grain/wall 0.9/0.5, static friction
/// grain/wall 0.16/0.45, rolling 0.09, twisting 0.01, dt = 1 us, semi-implicit Euler.
inline SystemConfig chrono_table1_config(double mu_rolling = 0.09) {
  SystemConfig c;
  c.contact_law = "hertz";
  c.rolling_model = "sunday";
  c.integrator = "semi_implicit_euler";
  c.dt_s = 1e-6;
  Material grain{"grain"};
  grain.young_modulus_Pa = 7e8;
  grain.poisson_ratio = 0.24;
  grain.density_kg_m3 = 2480;
  grain.cor_normal = 0.9;
  grain.mu_static = 0.16;
  grain.mu_rolling = mu_rolling;
  grain.mu_twisting = 0.01;
  set_paper_materials(c, grain, 0.5, 0.45);
  return c;
}

/// pkdgrav column of Table 1 as part 5 of the reproduction uses it
/// (examples/reproduction/part5_pkdgrav_1g.json): Hooke with k_N = 7.48e5 N/m (the paper gives no
/// k_N; about 1 % overlap of a bead at 1.2 m/s, docs/physics/contact-laws.md section 2.4) and
/// k_T = 2/7 k_N, COR grain/wall 0.9/0.5, eps_t = 1, mu_s = 1.0 (grain and wall), Zhang rolling
/// and twisting with mu_t = 1.3, leapfrog (KDK), dt = 1 us. Table 2's calibration varies mu_r and
/// beta.
inline SystemConfig pkdgrav_table1_config(double mu_rolling = 1.05, double shape_beta = 0.05) {
  SystemConfig c;
  c.contact_law = "hooke";
  c.rolling_model = "zhang";
  c.integrator = "leapfrog_kdk";
  c.dt_s = 1e-6;
  Material grain{"grain"};
  grain.density_kg_m3 = 2480;
  grain.cor_normal = 0.9;
  grain.cor_tangential = 1.0;
  grain.mu_static = 1.0;
  grain.mu_rolling = mu_rolling;
  grain.mu_twisting = 1.3;
  grain.kn_N_m = 7.48e5;
  grain.kt_N_m = 0;  // 2/7 k_N
  grain.shape_beta = shape_beta;
  set_paper_materials(c, grain, 0.5, 1.0);
  return c;
}

}  // namespace gravsweep

#include "engine/core/material.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "engine/core/error.h"

namespace gravsweep {

PairCoefficients compose_pair(const Material& a, const Material& b, const PairOverride* ov) {
  PairCoefficients c;
  // Hertz composition of elastic moduli (Chrono ChContactMaterialCompositeSMC,
  // docs/physics/contact-laws.md section 1.2).
  const double inv_E = (1 - a.poisson_ratio * a.poisson_ratio) / a.young_modulus_Pa +
                       (1 - b.poisson_ratio * b.poisson_ratio) / b.young_modulus_Pa;
  const double inv_G = 2 * (2 - a.poisson_ratio) * (1 + a.poisson_ratio) / a.young_modulus_Pa +
                       2 * (2 - b.poisson_ratio) * (1 + b.poisson_ratio) / b.young_modulus_Pa;
  c.E_eff_Pa = 1.0 / inv_E;
  c.G_eff_Pa = 1.0 / inv_G;
  // Chrono's default composition strategy: min() of the two materials.
  c.cor_normal = std::min(a.cor_normal, b.cor_normal);
  c.cor_tangential = std::min(a.cor_tangential, b.cor_tangential);
  c.mu_static = std::min(a.mu_static, b.mu_static);
  c.mu_rolling = std::min(a.mu_rolling, b.mu_rolling);
  c.mu_twisting = std::min(a.mu_twisting, b.mu_twisting);
  c.shape_beta = std::min(a.shape_beta, b.shape_beta);
  // Hooke springs: pkdgrav gives one kn per particle species and per wall; take the smaller.
  c.kn_N_m = std::min(a.kn_N_m, b.kn_N_m);
  const double kta = a.kt_N_m > 0 ? a.kt_N_m : 2.0 / 7.0 * a.kn_N_m;
  const double ktb = b.kt_N_m > 0 ? b.kt_N_m : 2.0 / 7.0 * b.kn_N_m;
  c.kt_N_m = std::min(kta, ktb);
  if (ov != nullptr) {
    if (ov->cor_normal) c.cor_normal = *ov->cor_normal;
    if (ov->cor_tangential) c.cor_tangential = *ov->cor_tangential;
    if (ov->mu_static) c.mu_static = *ov->mu_static;
    if (ov->mu_rolling) c.mu_rolling = *ov->mu_rolling;
    if (ov->mu_twisting) c.mu_twisting = *ov->mu_twisting;
    if (ov->shape_beta) c.shape_beta = *ov->shape_beta;
    if (ov->kn_N_m) {
      c.kn_N_m = *ov->kn_N_m;
      c.kt_N_m = 2.0 / 7.0 * c.kn_N_m;
    }
    if (ov->kt_N_m) c.kt_N_m = *ov->kt_N_m;
  }
  return c;
}

void validate_material(const Material& m) {
  auto fail = [&](const char* field, double value, const char* expected) {
    throw ConfigError(fmt::format("material '{}': {} = {} is invalid; expected {}", m.name, field, value, expected));
  };
  if (!(m.young_modulus_Pa > 0)) fail("young_modulus_Pa", m.young_modulus_Pa, "E > 0");
  if (!(m.poisson_ratio > 0 && m.poisson_ratio < 0.5)) fail("poisson_ratio", m.poisson_ratio, "nu in (0, 0.5)");
  if (!(m.density_kg_m3 > 0)) fail("density_kg_m3", m.density_kg_m3, "> 0");
  if (!(m.cor_normal > 0 && m.cor_normal <= 1)) fail("cor_normal", m.cor_normal, "COR in (0, 1]");
  if (!(m.cor_tangential > 0 && m.cor_tangential <= 1)) fail("cor_tangential", m.cor_tangential, "COR in (0, 1]");
  if (!(m.mu_static >= 0)) fail("mu_static", m.mu_static, ">= 0");
  if (!(m.mu_rolling >= 0)) fail("mu_rolling", m.mu_rolling, ">= 0");
  if (!(m.mu_twisting >= 0)) fail("mu_twisting", m.mu_twisting, ">= 0");
  if (!(m.kn_N_m >= 0)) fail("kn_N_m", m.kn_N_m, ">= 0");
  if (!(m.kt_N_m >= 0)) fail("kt_N_m", m.kt_N_m, ">= 0");
  if (!(m.shape_beta >= 0)) fail("shape_beta", m.shape_beta, ">= 0");
}

}  // namespace gravsweep

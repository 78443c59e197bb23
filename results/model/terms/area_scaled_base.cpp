// The gravity-scaled law with the projectile's size written out, for campaigns of several
// projectiles: R = phi m g + kappa_a g D^2 z + c_a D^2 v^2, one phi (dimensionless) and two
// densities (kg/m3) for all gravity levels and projectiles. kappa_a is the bed's bulk density
// times a depth-friction coefficient (lithostatic pressure rho g z on the projectile's
// cross-section, Brzinski et al. 2013); c_a is the bulk density times a drag coefficient
// (Katsuragi & Durian 2007: the drag length d1 grows as m / (rho_g D^2), so m v^2 / d1 =
// c_a D^2 v^2, independent of the projectile's mass). Dimensionless (docs/physics/force-laws.md):
// R / (m g) = phi + (kappa_a D^3 / m) z / D + (c_a D^3 / m) Fr^2 (v / vc)^2. For one projectile
// (10 cm, 1 kg) it is scaled_base + gravity_depth_friction with kappa = kappa_a D^2 and
// 1/d1 = c_a D^2 / m.
#include "results/model/term.h"

namespace gravsweep::results {

TermInfo area_scaled_base_term() {
  TermInfo t;
  t.name = "area_scaled_base";
  t.meaning =
      "gravity-scaled law over projectiles: phi m g + kappa_a g D^2 z + c_a D^2 v^2 (depth friction and drag on the "
      "cross-section, independent of the projectile's mass)";
  t.references = "Katsuragi & Durian 2007 Nat. Phys. 3:420 (d1 ~ m / rho_g D^2); Brzinski et al. 2013 PRL 111:168002";
  t.signature = "-";
  t.params = {"phi", "kappa_a_kg_m3", "c_a_kg_m3"};
  t.per_gravity = false;
  t.baseline_only = true;
  t.features = [](const TermContext& c, double* out) {
    const double area = c.diameter_m * c.diameter_m;
    out[0] = c.mass_kg * c.g_m_s2;
    out[1] = c.g_m_s2 * area * c.z_m;
    out[2] = area * c.v_m_s * c.v_m_s;
  };
  // The sweep's law for the 10 cm, 1 kg sphere: kappa 31.6 kg/m, 1/d1 14.5 1/m (GRAVITY.md).
  t.typical = [](double, double, double) { return std::vector<double>{0.7, 3160.0, 1450.0}; };
  return t;
}

}  // namespace gravsweep::results

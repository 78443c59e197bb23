// Finite-size drag over projectiles: R = c_g d D v^2, with d the bed's grain diameter and D the
// projectile's, c_g in kg/m3 (docs/physics/force-laws.md section 2.2). Added to area_scaled_base's
// c_a D^2 v^2 the drag per unit of cross-section is c_a (1 + (c_g / c_a) d / D): it grows as the
// projectile spans fewer grains, the trend of the projectile sweep (5 cm stops shallower than a
// drag on D^2 says; GRAVITY.md, "Beyond one projectile"). Seguin et al. 2011 and Katsuragi &
// Durian 2007 both report a resistance that does not scale with D^2 once D/d falls to a few.
// One sweep over D at one d cannot tell d / D from any other power of D: the term is the
// simplest finite-size correction, not a measured law of d.
#include "results/model/term.h"

namespace gravsweep::results {

TermInfo grain_drag_term() {
  TermInfo t;
  t.name = "grain_drag";
  t.meaning = "inertial drag on the projectile's diameter times the grain diameter: c_g d D v^2 (finite-size drag)";
  t.references =
      "Katsuragi & Durian 2007 Nat. Phys. 3:420; Seguin, Bertho, Martinez, Crassous & Gondret 2011 "
      "PRE 84:011301";
  t.signature = "across projectiles: a drag on D^2 stops the small projectile too deep, at every mass";
  t.params = {"c_g_kg_m3"};
  t.per_gravity = false;
  t.across_diameters = true;
  t.features = [](const TermContext& c, double* out) {
    out[0] = c.grain_diameter_m * c.diameter_m * c.v_m_s * c.v_m_s;
  };
  // The projectile sweep's fit (GRAVITY.md): c_g = 23,580 kg/m3, at D = 10 cm and d = 1 cm the
  // drag of c_a = c_g d / D = 2358 kg/m3 on D^2.
  t.typical = [](double, double, double) { return std::vector<double>{23580.0}; };
  return t;
}

}  // namespace gravsweep::results

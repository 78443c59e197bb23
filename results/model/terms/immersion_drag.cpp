// Partial-immersion inertial drag (docs/physics/force-laws.md section 2.2; Goldman & Umbanhowar
// 2008; Clark & Behringer 2013): h(z) = (m/d1) A(z)/A_max with A(z) = pi (D z - z^2) for z < D/2.
// As a correction to the baseline's constant m/d1: R = c m v^2 (A(z)/A_max - 1), c in 1/m (c = 1/d1
// gives the full cross-section law).
#include <algorithm>

#include "results/model/term.h"

namespace gravsweep::results {

TermInfo immersion_drag_term() {
  TermInfo t;
  t.name = "immersion_drag";
  t.meaning = "inertial drag growing with the immersed cross-section while z < D/2";
  t.references = "Goldman & Umbanhowar 2008 PRE 77:021308; Clark & Behringer 2013 EPL";
  t.signature = "residual ~ v^2 confined to z < D/2; the measured peak comes after contact";
  t.params = {"c_1_m"};
  t.per_gravity = true;
  t.features = [](const TermContext& c, double* out) {
    const double D = c.diameter_m;
    const double z = std::clamp(c.z_m, 0.0, 0.5 * D);
    const double frac = 4.0 * z * (D - z) / (D * D);  // A(z) / A(D/2)
    out[0] = c.mass_kg * c.v_m_s * c.v_m_s * (frac - 1.0);
  };
  t.typical = [](double, double, double) { return std::vector<double>{25.0}; };
  return t;
}

}  // namespace gravsweep::results

// Rate-linear (viscous) drag R = b v (docs/physics/force-laws.md section 2.2;
// de Bruyn & Walsh 2004).
#include "results/model/term.h"

namespace gravsweep::results {

TermInfo viscous_drag_term() {
  TermInfo t;
  t.name = "viscous_drag";
  t.meaning = "drag linear in speed (viscous-like)";
  t.references = "de Bruyn & Walsh 2004 Can. J. Phys. 82:439";
  t.signature = "residual ~ -v: largest just after contact; r vs v changes sign against a v^2 fit";
  t.params = {"b_N_s_m"};
  t.per_gravity = false;  // a rate effect, not loaded by gravity
  t.features = [](const TermContext& c, double* out) { out[0] = c.v_m_s; };
  // b = 4 N s/m per kg of projectile: small against the 1 g friction, dominant at low g and speed.
  t.typical = [](double, double m, double) { return std::vector<double>{4.0 * m}; };
  return t;
}

}  // namespace gravsweep::results

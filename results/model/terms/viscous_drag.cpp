// Rate-linear (viscous) drag R = b v (force-laws.md 2.2 row 3; de Bruyn & Walsh 2004).
#include "results/model/term.h"

namespace gravsweep::results {

TermInfo viscous_drag_term() {
  TermInfo t;
  t.name = "viscous_drag";
  t.meaning = "drag linear in speed (viscous-like)";
  t.references = "de Bruyn & Walsh 2004 Can. J. Phys. 82:439";
  t.signature = "residual ~ -v: largest just after contact; r vs v changes sign against a v^2 fit";
  t.params = {"b_N_s_m"};
  t.per_gravity = true;
  t.features = [](const TermContext& c, double* out) { out[0] = c.v_m_s; };
  // Comparable with the friction at 1 m/s: b = 1.5 m g / (1 m/s).
  t.typical = [](double g, double m, double) { return std::vector<double>{1.5 * m * g}; };
  return t;
}

}  // namespace gravsweep::results

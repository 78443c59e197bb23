// Gravity-loaded depth friction R = kappa g z with one kappa for all gravity levels
// (docs/physics/force-laws.md section 2.2; Brzinski et al. 2013; Altshuler et al. 2014). Parameter
// kappa (kg/m).
#include "results/model/term.h"

namespace gravsweep::results {

TermInfo gravity_depth_friction_term() {
  TermInfo t;
  t.name = "gravity_depth_friction";
  t.meaning = "depth friction loaded by lithostatic pressure: k = kappa g, one kappa for all g";
  t.references = "Brzinski, Mayor & Durian 2013 PRL 111:168002; Altshuler et al. 2014 GRL";
  t.signature = "only across a g sweep: fitted k(g) on a line through the origin";
  t.params = {"kappa_kg_m"};
  t.per_gravity = false;
  t.features = [](const TermContext& c, double* out) { out[0] = c.g_m_s2 * c.z_m; };
  t.typical = [](double, double m, double) { return std::vector<double>{1.6 * m / 0.03}; };
  return t;
}

}  // namespace gravsweep::results

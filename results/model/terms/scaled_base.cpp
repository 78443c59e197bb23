// The paper's baseline with its gravity dependence written out (paper II's Froude scaling;
// Sunday et al. 2021 Sect. 5: "collision behaviour scaled by gravity"): R = phi m g + m v^2 / d1,
// one phi (dimensionless) and one 1/d1 (1/m) for every gravity level. A campaign whose
// resistance follows g is fitted by two numbers over all levels; a resistance that does not
// follow g (cohesion) is left in the residuals for `model rank` to find, where a per-level f0
// (the term base) would absorb it level by level.
#include "results/model/term.h"

namespace gravsweep::results {

TermInfo scaled_base_term() {
  TermInfo t;
  t.name = "scaled_base";
  t.meaning = "gravity-scaled friction phi m g plus inertial drag m v^2/d1, one law for all gravity levels";
  t.references = "Sunday et al. 2021 Eq. 1 and Sect. 5; Sunday et al. 2022 (paper II, Froude scaling)";
  t.signature = "-";
  t.params = {"phi", "inv_d1_1_m"};
  t.per_gravity = false;
  t.baseline_only = true;
  t.features = [](const TermContext& c, double* out) {
    out[0] = c.mass_kg * c.g_m_s2;
    out[1] = c.mass_kg * c.v_m_s * c.v_m_s;
  };
  t.typical = [](double, double, double) { return std::vector<double>{1.6, 25.0}; };
  return t;
}

}  // namespace gravsweep::results

// The paper's baseline (Sunday et al. 2021 Eq. 1 with f = f0, h = m/d1; Murdoch et al. 2021):
// R = f0 + m v^2 / d1. Parameters f0 (N) and 1/d1 (1/m), per gravity level as in Table 3.
#include "results/model/term.h"

namespace gravsweep::results {

TermInfo base_term() {
  TermInfo t;
  t.name = "base";
  t.meaning = "constant quasi-static friction f0 plus inertial drag m v^2/d1 (Poncelet)";
  t.references = "Sunday et al. 2021 Eq. 1-4; Murdoch et al. 2021; Katsuragi & Durian 2007";
  t.signature = "-";
  t.params = {"f0_N", "inv_d1_1_m"};
  t.per_gravity = true;
  t.gravity_form = "scaled_base";
  t.features = [](const TermContext& c, double* out) {
    out[0] = 1.0;
    out[1] = c.mass_kg * c.v_m_s * c.v_m_s;
  };
  t.typical = [](double g, double m, double) { return std::vector<double>{1.6 * m * g, 25.0}; };
  return t;
}

}  // namespace gravsweep::results

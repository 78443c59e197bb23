// Depth-linear quasi-static friction R = k z (docs/physics/force-laws.md section 2.2; Katsuragi &
// Durian 2007, Tsimring & Volfson 2005). Parameter k (N/m), per gravity level.
#include "results/model/term.h"

namespace gravsweep::results {

TermInfo depth_friction_term() {
  TermInfo t;
  t.name = "depth_friction";
  t.meaning = "quasi-static friction growing linearly with depth (hydrostatic-like pressure)";
  t.references =
      "Katsuragi & Durian 2007 Nat. Phys. 3:420; Tsimring & Volfson 2005; "
      "Brzinski, Mayor & Durian 2013 PRL 111:168002";
  t.signature = "residual ~ -z, independent of v; f0 fitted per trial grows with impact speed";
  t.params = {"k_N_m"};
  t.per_gravity = true;
  t.gravity_form = "gravity_depth_friction";
  t.features = [](const TermContext& c, double* out) { out[0] = c.z_m; };
  // f0 (1 + z / lambda) with f0 = 1.6 m g and lambda = 3 cm.
  t.typical = [](double g, double m, double) { return std::vector<double>{1.6 * m * g / 0.03}; };
  return t;
}

}  // namespace gravsweep::results

// Bottom-boundary stiffening R = F_b exp(-(H_fill - z)/lambda), lambda = 1 cm
// (docs/physics/force-laws.md section 2.2; Stone et al. 2004; Seguin, Bertho & Gondret 2008).
// Parameter F_b (N), shared.
#include <cmath>

#include "results/model/term.h"

namespace gravsweep::results {

TermInfo bottom_stiffening_term() {
  TermInfo t;
  t.name = "bottom_stiffening";
  t.meaning = "resistance rising exponentially as the projectile nears the container floor";
  t.references = "Stone et al. 2004 Nature 427:503; Seguin, Bertho & Gondret 2008 PRE 78:010301";
  t.signature = "negative residual growing as z -> H_fill; vanishes in deep beds";
  t.params = {"Fb_N"};
  t.per_gravity = true;
  t.features = [](const TermContext& c, double* out) { out[0] = std::exp(-(c.fill_height_m - c.z_m) / 0.01); };
  t.typical = [](double g, double m, double) { return std::vector<double>{8.0 * m * g}; };
  return t;
}

}  // namespace gravsweep::results

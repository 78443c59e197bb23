// Cohesion: a constant resisting force f_c that does not scale with g, shared by all gravity
// levels (docs/physics/force-laws.md section 2.2; Yeo et al. 2025). Identifiable only against a
// baseline whose friction is gravity-scaled; against per-gravity f0 it is absorbed and never ranks.
#include "results/model/term.h"

namespace gravsweep::results {

TermInfo cohesion_term() {
  TermInfo t;
  t.name = "cohesion";
  t.meaning = "constant friction independent of gravity (cohesion)";
  t.references = "Yeo, Glade, Quillen & Askari 2025 arXiv:2507.14645";
  t.signature = "f0(g) with a positive intercept; matters more at low g";
  t.params = {"fc_N"};
  t.per_gravity = false;
  t.features = [](const TermContext&, double* out) { out[0] = 1.0; };
  t.typical = [](double, double m, double) { return std::vector<double>{0.5 * m}; };
  return t;
}

}  // namespace gravsweep::results

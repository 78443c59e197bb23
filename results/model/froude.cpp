// The design's Froude numbers (see froude.h).
#include "results/model/froude.h"

#include <cmath>

#include <algorithm>
#include <cstddef>

namespace gravsweep::results {

std::vector<int> froude_groups(const std::vector<double>& ln_froude) {
  std::vector<std::size_t> order(ln_froude.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return ln_froude[a] < ln_froude[b]; });
  std::vector<int> group(ln_froude.size(), 0);
  int g = -1;
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (k == 0 || ln_froude[order[k]] - ln_froude[order[k - 1]] > kSameFroudeLn) ++g;
    group[order[k]] = g;
  }
  return group;
}

double impact_froude(const MeasuredTrial& t) {
  return t.processed.metrics.vc_m_s / std::sqrt(t.info.gravity_m_s2 * t.info.projectile_diameter_m);
}

}  // namespace gravsweep::results

// The regime map of a fitted collision law (see regimes.h).
#include "results/model/fit.h"
#include "results/model/predict.h"
#include "results/model/regimes.h"

#include <algorithm>
#include <cmath>

#include "results/model/froude.h"
#include "results/model/model_internal.h"

namespace gravsweep::results {

using namespace detail;

ResistanceSplit split_resistance(const FittedModel& law, const TermContext& at) {
  TermContext at_rest = at;
  at_rest.v_m_s = 0;
  ResistanceSplit s;
  s.quasi_static_N = law.force(at_rest);
  s.dynamic_N = law.force(at) - s.quasi_static_N;
  return s;
}

double surface_crossover_froude(const FittedModel& law, const TermContext& at) {
  TermContext c = at;
  c.z_m = 0;
  c.t_since_contact_s = 0;
  const double scale_m_s = std::sqrt(c.g_m_s2 * c.diameter_m);
  // dynamic - quasi-static at the surface, at speed v
  auto excess = [&](double v) {
    c.v_m_s = v;
    const ResistanceSplit s = split_resistance(law, c);
    return s.quasi_static_N > 0 ? s.dynamic_N - s.quasi_static_N : NAN;
  };
  double lo = 0, hi = kCrossoverMaxFroude * scale_m_s;
  if (!(excess(lo) < 0) || !(excess(hi) > 0)) return NAN;
  for (int i = 0; i < 100 && hi - lo > 1e-12 * scale_m_s; ++i) {
    const double mid = 0.5 * (lo + hi);
    (excess(mid) > 0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi) / scale_m_s;
}

namespace {

/// The motion of one drop under the law, with the impulse and the work of each part and the first
/// state where the dynamic part is no longer the larger.
RegimeTrial regimes_of(const FittedModel& law, const MeasuredTrial& t) {
  RegimeTrial r;
  const TermContext c0 = context(t.info);
  r.g_m_s2 = c0.g_m_s2;
  r.vc_m_s = c0.vc_m_s;
  const double scale_m_s = std::sqrt(c0.g_m_s2 * c0.diameter_m);
  r.impact_froude = c0.vc_m_s / scale_m_s;
  r.surface_crossover_froude = surface_crossover_froude(law, c0);
  double impulse_qs = 0, impulse_all = 0, work_qs = 0, work_all = 0;
  double prev_excess = NAN, prev_v = NAN, prev_z = NAN;
  bool first = true, starts_dynamic = false, crossed = false;
  // The first state where the dynamic part is no longer the larger, interpolated linearly between
  // steps; none when the drop starts in the quasi-static regime.
  auto watch = [&](double z, double v, double excess) {
    if (first)
      starts_dynamic = excess > 0;
    else if (starts_dynamic && !crossed && !(excess > 0)) {
      const double f = prev_excess / (prev_excess - excess);
      r.crossover_froude = (prev_v + f * (v - prev_v)) / scale_m_s;
      r.crossover_depth_m = prev_z + f * (z - prev_z);
      crossed = true;
    }
    first = false;
    prev_excess = excess, prev_v = v, prev_z = z;
  };
  TermContext c = c0;
  const Prediction p =
      integrate_motion(law, c0, prediction_horizon_s(c0), [&](double t_s, double z, double v, double dt) {
        c.z_m = z, c.v_m_s = v, c.t_since_contact_s = t_s;
        const ResistanceSplit s = split_resistance(law, c);
        impulse_qs += s.quasi_static_N * dt, impulse_all += (s.quasi_static_N + s.dynamic_N) * dt;
        work_qs += s.quasi_static_N * v * dt, work_all += (s.quasi_static_N + s.dynamic_N) * v * dt;
        watch(z, v, s.dynamic_N - s.quasi_static_N);
      });
  r.stopped = p.stopped;
  if (p.stopped) {
    c.z_m = p.zstop_m, c.v_m_s = 0, c.t_since_contact_s = p.tstop_s;
    const ResistanceSplit s = split_resistance(law, c);
    watch(p.zstop_m, 0.0, s.dynamic_N - s.quasi_static_N);
  }
  if (impulse_all > 0) r.quasi_static_impulse_pct = 100 * impulse_qs / impulse_all;
  if (work_all > 0) r.quasi_static_work_pct = 100 * work_qs / work_all;
  return r;
}

}  // namespace

std::vector<RegimeTrial> regime_map(const FittedModel& law, const Campaign& c) {
  std::vector<RegimeTrial> out;
  for (std::size_t i = 0; i < c.trials.size(); ++i) {
    RegimeTrial r = regimes_of(law, c.trials[i]);
    r.trial = i;
    out.push_back(r);
  }
  return out;
}

namespace {

/// ln Fr where the (ln Fr, dynamic share %) polyline first crosses 50 % upwards; NaN when it does not.
double crossing_of(const std::vector<std::pair<double, double>>& pts) {
  for (std::size_t k = 1; k < pts.size(); ++k) {
    const auto [x0, y0] = pts[k - 1];
    const auto [x1, y1] = pts[k];
    if (y0 < 50 && y1 >= 50) return std::exp(x0 + (x1 - x0) * (50 - y0) / (y1 - y0));
  }
  return NAN;
}

}  // namespace

double whole_collision_crossover(const std::vector<RegimeTrial>& map, CrossoverShare share) {
  std::vector<double> ln_fr, dynamic_pct;
  for (const auto& r : map) {
    const double qs = share == CrossoverShare::impulse ? r.quasi_static_impulse_pct : r.quasi_static_work_pct;
    if (std::isfinite(r.impact_froude) && r.impact_froude > 0 && std::isfinite(qs)) {
      ln_fr.push_back(std::log(r.impact_froude));
      dynamic_pct.push_back(100 - qs);
    }
  }
  // The design's Froude numbers (froude_groups, numbered from the smallest): mean ln Fr and share.
  const std::vector<int> group = froude_groups(ln_fr);
  const int n_groups = group.empty() ? 0 : *std::max_element(group.begin(), group.end()) + 1;
  std::vector<std::pair<double, double>> mean(static_cast<std::size_t>(n_groups), {0.0, 0.0});
  std::vector<double> count(static_cast<std::size_t>(n_groups), 0.0);
  for (std::size_t k = 0; k < group.size(); ++k) {
    const auto g = static_cast<std::size_t>(group[k]);
    mean[g].first += ln_fr[k];
    mean[g].second += dynamic_pct[k];
    count[g] += 1;
  }
  for (std::size_t g = 0; g < mean.size(); ++g) mean[g] = {mean[g].first / count[g], mean[g].second / count[g]};
  return crossing_of(mean);
}

namespace {

/// f(law) with its standard deviation from the law's covariance: central differences of 1 % of
/// each constant, delta method.
template <class F>
CrossoverEstimate with_sd(const FittedModel& law, F f) {
  CrossoverEstimate e;
  e.froude = f(law);
  const Eigen::Index n = law.coef.size();
  Eigen::VectorXd d(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    FittedModel up = law, down = law;
    const double h = 0.01 * std::max(std::abs(law.coef(j)), 1e-12);
    up.coef(j) += h, down.coef(j) -= h;
    d(j) = (f(up) - f(down)) / (2 * h);
  }
  if (d.allFinite()) e.sd = std::sqrt(std::max(0.0, d.dot(law.cov * d)));
  return e;
}

}  // namespace

CrossoverEstimate whole_collision_crossover(const FittedModel& law, const Campaign& c, CrossoverShare share) {
  return with_sd(law, [&](const FittedModel& m) { return whole_collision_crossover(regime_map(m, c), share); });
}

CrossoverEstimate surface_crossover(const FittedModel& law, const Trial& at) {
  const TermContext ctx = detail::context(at);
  return with_sd(law, [&](const FittedModel& m) { return surface_crossover_froude(m, ctx); });
}

}  // namespace gravsweep::results

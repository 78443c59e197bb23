// Collision models (see model.h): residuals along axes and the ranking of candidate terms.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "results/model/model.h"
#include "results/model/model_internal.h"

namespace gravsweep::results {

using namespace detail;

// ---------------------------------------------------------------------------------------------
// Residuals along axes

std::vector<AxisResidual> residual_axes(const FittedModel& m, const Campaign& c) {
  struct S {
    double r, w;
    double x[6];
    int trial;
  };
  static const char* names[6] = {"depth_m", "speed_m_s", "time_since_contact_s",
                                 "gravity_m_s2", "impact_velocity_m_s", "fill_height_m"};
  std::vector<S> s;
  for (std::size_t ti = 0; ti < c.trials.size(); ++ti) {
    const auto& t = c.trials[ti];
    const double n = static_cast<double>(t.fit_end - t.fit_begin);
    for (std::size_t k = t.fit_begin; k < t.fit_end; ++k) {
      const TermContext ctx = context(t, k);
      const double g = t.info.gravity_m_s2;
      const double a_model = m.force(ctx) / t.info.projectile_mass_kg - g;
      S q;
      q.r = (t.processed.accel_up_m_s2[k] - a_model) / g;
      q.w = 1.0 / n;
      q.x[0] = ctx.z_m;
      q.x[1] = ctx.v_m_s;
      q.x[2] = ctx.t_since_contact_s;
      q.x[3] = g;
      q.x[4] = t.info.impact_velocity_m_s;
      q.x[5] = t.info.fill_height_m;
      q.trial = static_cast<int>(ti);
      s.push_back(q);
    }
  }
  std::vector<AxisResidual> out;
  if (s.empty()) return out;
  double W = 0, M = 0;
  for (const auto& q : s) W += q.w, M += q.w * q.r;
  M /= W;
  double V = 0;
  for (const auto& q : s) V += q.w * (q.r - M) * (q.r - M);
  for (int a = 0; a < 6; ++a) {
    AxisResidual ar;
    ar.axis = names[a];
    std::vector<std::size_t> idx(s.size());
    std::iota(idx.begin(), idx.end(), 0);
    std::sort(idx.begin(), idx.end(), [&](std::size_t i, std::size_t j) { return s[i].x[a] < s[j].x[a]; });
    const int nb = 6;
    double acc_w = 0;
    std::size_t pos = 0;
    double between = 0;
    std::vector<double> half_even, half_odd;  // bin means over even- and odd-numbered trials
    for (int b = 0; b < nb && pos < idx.size(); ++b) {
      const double target = W * (b + 1) / nb;
      double bw = 0, br = 0, bx = 0;
      double hw[2] = {0, 0}, hr[2] = {0, 0};
      const std::size_t pos0 = pos;
      const double x_first = s[idx[pos]].x[a];
      while (pos < idx.size() && (acc_w < target || b == nb - 1)) {
        const auto& q = s[idx[pos]];
        bw += q.w, br += q.w * q.r, bx += q.w * q.x[a];
        acc_w += q.w;
        ++pos;
        // keep equal axis values together (trial-level axes)
        while (pos < idx.size() && s[idx[pos]].x[a] == s[idx[pos - 1]].x[a] && a >= 3) {
          const auto& q2 = s[idx[pos]];
          bw += q2.w, br += q2.w * q2.r, bx += q2.w * q2.x[a];
          acc_w += q2.w;
          ++pos;
        }
      }
      (void)x_first;
      if (bw <= 0) continue;
      for (std::size_t k = pos0; k < pos; ++k) {
        const auto& q = s[idx[k]];
        hw[q.trial % 2] += q.w, hr[q.trial % 2] += q.w * q.r;
      }
      if (hw[0] > 0 && hw[1] > 0) {
        half_even.push_back(hr[0] / hw[0]);
        half_odd.push_back(hr[1] / hw[1]);
      }
      ar.bin_center.push_back(bx / bw);
      ar.bin_mean_r_over_g.push_back(br / bw);
      between += bw * std::pow(br / bw - M, 2);
    }
    ar.eta2 = V > 0 ? between / V : 0;
    // Split-half reproducibility: the bin profile of the even-numbered trials against that of the
    // odd-numbered ones (disjoint sets of trials), Pearson r over the bins.
    if (half_even.size() >= 3) {
      const double n = static_cast<double>(half_even.size());
      double me = 0, mo = 0;
      for (std::size_t i = 0; i < half_even.size(); ++i) me += half_even[i] / n, mo += half_odd[i] / n;
      double see = 0, soo = 0, seo = 0;
      for (std::size_t i = 0; i < half_even.size(); ++i) {
        see += (half_even[i] - me) * (half_even[i] - me);
        soo += (half_odd[i] - mo) * (half_odd[i] - mo);
        seo += (half_even[i] - me) * (half_odd[i] - mo);
      }
      ar.split_half_r = see > 0 && soo > 0 ? seo / std::sqrt(see * soo) : 0;
    }
    if (a < 3) {
      // Within-trial slope of r against the axis; sign test over trials.
      std::vector<double> sx(c.trials.size()), sy(c.trials.size()), sxx(c.trials.size()),
          sxy(c.trials.size()), sn(c.trials.size());
      for (const auto& q : s) {
        const auto t = static_cast<std::size_t>(q.trial);
        sx[t] += q.x[a], sy[t] += q.r, sxx[t] += q.x[a] * q.x[a], sxy[t] += q.x[a] * q.r, sn[t] += 1;
      }
      for (std::size_t t = 0; t < c.trials.size(); ++t) {
        if (sn[t] < 3) continue;
        const double den = sn[t] * sxx[t] - sx[t] * sx[t];
        if (den <= 0) continue;
        const double slope = (sn[t] * sxy[t] - sx[t] * sy[t]) / den;
        (slope > 0 ? ar.trials_positive : ar.trials_negative)++;
      }
      const int n = ar.trials_positive + ar.trials_negative;
      const int k = std::max(ar.trials_positive, ar.trials_negative);
      ar.slope_sign_trials_p = std::min(1.0, 2.0 * binom_tail_half(k, n));
    }
    out.push_back(ar);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Discovery

namespace {

bool structured(const std::vector<AxisResidual>& axes, std::string& where) {
  const AxisResidual* best = nullptr;
  for (const auto& a : axes) {
    if (a.axis == "gravity_m_s2" || a.axis == "impact_velocity_m_s" || a.axis == "fill_height_m") {
      if (a.eta2 >= 0.25 && (!best || a.eta2 > best->eta2)) best = &a;
      continue;
    }
    const bool monotone = a.eta2 >= 0.15 && a.slope_sign_trials_p < 1e-4;
    const bool reproducible = a.eta2 >= 0.05 && a.split_half_r >= 0.9;
    if ((monotone || reproducible) && (!best || a.eta2 > best->eta2)) best = &a;
  }
  if (!best) return false;
  std::string bins;
  for (std::size_t i = 0; i < best->bin_center.size(); ++i)
    bins += fmt::format("{}{:.3g}:{:+.3f}", i ? ", " : "", best->bin_center[i], best->bin_mean_r_over_g[i]);
  where = fmt::format("residual varies with {} (eta^2 = {:.2f}, split-half r = {:.2f}; mean residual/g by bin: {})",
                      best->axis, best->eta2, best->split_half_r, bins);
  return true;
}

}  // namespace

Discovery discover(const Campaign& c, const ModelSpec& baseline, int folds, double alpha,
                   double min_improvement, int max_rounds) {
  Discovery d;
  d.baseline = baseline.name();
  ModelSpec current = baseline;
  d.residual_before = residual_axes(fit_model(current, c), c);
  for (int round = 0; round < max_rounds; ++round) {
    const HeldOut h0 = cross_validate(current, c, folds, 1, false);
    std::vector<Candidate> cands;
    for (const auto& term : term_registry()) {
      bool present = false;
      for (const auto& t : current.terms) present = present || t.term->name == term.name;
      if (present) continue;
      ModelSpec s = current;
      s.terms.push_back({&term, term.per_gravity, 1.0});
      const HeldOut h1 = cross_validate(s, c, folds, 1, false);
      Candidate cd;
      cd.term = term.name;
      double sum = 0;
      std::vector<double> rel_all;
      for (std::size_t i = 0; i < c.trials.size(); ++i) {
        if (!std::isfinite(h0.trace_mse[i]) || !std::isfinite(h1.trace_mse[i]) || h0.trace_mse[i] <= 0) continue;
        const double rel = (h0.trace_mse[i] - h1.trace_mse[i]) / h0.trace_mse[i];
        rel_all.push_back(rel);
        sum += rel;
        ++cd.trials;
        if (rel > 0) ++cd.trials_better;
      }
      cd.mean_rel_improvement = cd.trials ? sum / cd.trials : 0;
      cd.p_value = signed_rank_p(rel_all);
      cands.push_back(cd);
    }
    const double level = alpha / std::max<std::size_t>(1, cands.size());
    for (auto& cd : cands) cd.significant = cd.p_value < level && cd.mean_rel_improvement >= min_improvement;
    std::sort(cands.begin(), cands.end(), [](const Candidate& a, const Candidate& b) {
      if (a.significant != b.significant) return a.significant;
      return a.mean_rel_improvement > b.mean_rel_improvement;
    });
    d.rounds.push_back(cands);
    if (cands.empty() || !cands.front().significant) break;
    const TermInfo& win = find_term(cands.front().term);
    current.terms.push_back({&win, win.per_gravity, 1.0});
    d.added.push_back(win.name);
  }
  d.residual_after = residual_axes(fit_model(current, c), c);
  std::string where;
  const bool left = structured(d.residual_after, where);
  d.structure_left = left;
  if (d.added.empty()) {
    d.verdict = left ? "structure left that no candidate explains: " + where
                     : "no missing effect found: no candidate term improves the held-out trials "
                       "significantly and the residuals show no structure";
  } else {
    const auto& first = d.rounds.front().front();
    const TermInfo& w = find_term(first.term);
    d.verdict = fmt::format(
        "missing effect: {} ({}); held-out trace error down {:.0f} % on average, better on {} of {} "
        "trials (signed-rank test over trials p = {:.1e}); references: {}",
        w.name, w.meaning, 100 * first.mean_rel_improvement, first.trials_better, first.trials,
        first.p_value, w.references);
    for (std::size_t i = 1; i < d.added.size(); ++i) d.verdict += "; then " + d.added[i];
    if (left) d.verdict += "; structure left that no candidate explains: " + where;
  }
  return d;
}

}  // namespace gravsweep::results

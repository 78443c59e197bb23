// Residuals of a fitted model along the state and trial axes (residual_axes.h): where a
// model fails, binned in equal-weight bins and tested for structure (eta^2, a split-half profile,
// a sign test of the within-trial slope over trials).
#include <algorithm>
#include <cmath>
#include <numeric>

#include "results/model/fit.h"
#include "results/model/residual_axes.h"
#include "results/model/model_internal.h"

namespace gravsweep::results {

namespace {

constexpr int kAxes = 6;
constexpr int kFirstTrialAxis = 3;  ///< axes from this one on are constant within a trial
constexpr int kBins = 6;
const char* const kAxisNames[kAxes] = {"depth_m",      "speed_m_s",        "time_since_contact_s",
                                       "gravity_m_s2", "impact_speed_m_s", "fill_height_m"};

/// One sample of a trial's fitted window: the residual of the acceleration in units of g, its
/// weight (1 / the trial's sample count: every trial weighs one), its value on each axis.
struct ResidualSample {
  double r_over_g, weight;
  double x[kAxes];
  int trial;
};

std::vector<ResidualSample> residual_samples(const FittedModel& m, const Campaign& c) {
  std::vector<ResidualSample> s;
  for (std::size_t ti = 0; ti < c.trials.size(); ++ti) {
    const auto& t = c.trials[ti];
    const double n = static_cast<double>(t.fit_end - t.fit_begin);
    for (std::size_t k = t.fit_begin; k < t.fit_end; ++k) {
      const TermContext ctx = detail::context(t, k);
      const double g = t.info.gravity_m_s2;
      const double a_model = m.force(ctx) / t.info.projectile_mass_kg - g;
      s.push_back({(t.processed.accel_up_m_s2[k] - a_model) / g,
                   1.0 / n,
                   {ctx.z_m, ctx.v_m_s, ctx.t_since_contact_s, g, t.info.impact_speed_m_s, t.info.fill_height_m},
                   static_cast<int>(ti)});
    }
  }
  return s;
}

/// Pearson r of two profiles of equal length (0 when either is flat).
double pearson_r(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = static_cast<double>(a.size());
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) ma += a[i] / n, mb += b[i] / n;
  double saa = 0, sbb = 0, sab = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
    sab += (a[i] - ma) * (b[i] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0;
}

/// kBins bins of equal weight along axis `a` (equal values of a trial-level axis stay in one bin):
/// bin centres and mean residuals, eta^2 (between-bin share of the variance V about the mean M,
/// total weight W), and the split-half r of the bin profiles of even- and odd-numbered trials.
void bin_profile(const std::vector<ResidualSample>& s, int a, double total_weight, double mean, double variance,
                 AxisResidual& ar) {
  std::vector<std::size_t> idx(s.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](std::size_t i, std::size_t j) { return s[i].x[a] < s[j].x[a]; });
  double acc_w = 0, between = 0;
  std::size_t pos = 0;
  std::vector<double> half_even, half_odd;  // bin means over even- and odd-numbered trials
  for (int b = 0; b < kBins && pos < idx.size(); ++b) {
    const double target = total_weight * (b + 1) / kBins;
    double w = 0, wr = 0, wx = 0;
    const std::size_t first = pos;
    const auto take = [&](const ResidualSample& q) {
      w += q.weight, wr += q.weight * q.r_over_g, wx += q.weight * q.x[a];
      acc_w += q.weight;
      ++pos;
    };
    while (pos < idx.size() && (acc_w < target || b == kBins - 1)) {
      take(s[idx[pos]]);
      while (pos < idx.size() && a >= kFirstTrialAxis && s[idx[pos]].x[a] == s[idx[pos - 1]].x[a]) take(s[idx[pos]]);
    }
    if (w <= 0) continue;
    double hw[2] = {0, 0}, hr[2] = {0, 0};
    for (std::size_t k = first; k < pos; ++k) {
      const auto& q = s[idx[k]];
      hw[q.trial % 2] += q.weight, hr[q.trial % 2] += q.weight * q.r_over_g;
    }
    if (hw[0] > 0 && hw[1] > 0) {
      half_even.push_back(hr[0] / hw[0]);
      half_odd.push_back(hr[1] / hw[1]);
    }
    ar.bin_center.push_back(wx / w);
    ar.bin_mean_r_over_g.push_back(wr / w);
    between += w * std::pow(wr / w - mean, 2);
  }
  ar.eta2 = variance > 0 ? between / variance : 0;
  if (half_even.size() >= 3) ar.split_half_r = pearson_r(half_even, half_odd);
}

/// The sign of each trial's least-squares slope of the residual along state axis `a`, and the
/// two-sided sign test over trials.
void within_trial_slopes(const std::vector<ResidualSample>& s, std::size_t trials, int a, AxisResidual& ar) {
  std::vector<double> sx(trials), sy(trials), sxx(trials), sxy(trials), sn(trials);
  for (const auto& q : s) {
    const auto t = static_cast<std::size_t>(q.trial);
    sx[t] += q.x[a], sy[t] += q.r_over_g, sxx[t] += q.x[a] * q.x[a], sxy[t] += q.x[a] * q.r_over_g, sn[t] += 1;
  }
  for (std::size_t t = 0; t < trials; ++t) {
    if (sn[t] < 3) continue;
    const double den = sn[t] * sxx[t] - sx[t] * sx[t];
    if (den <= 0) continue;
    const double slope = (sn[t] * sxy[t] - sx[t] * sy[t]) / den;
    (slope > 0 ? ar.trials_positive : ar.trials_negative)++;
  }
  const int n = ar.trials_positive + ar.trials_negative;
  const int k = std::max(ar.trials_positive, ar.trials_negative);
  ar.slope_sign_trials_p = std::min(1.0, 2.0 * detail::binom_tail_half(k, n));
}

}  // namespace

std::vector<AxisResidual> residual_axes(const FittedModel& m, const Campaign& c) {
  const std::vector<ResidualSample> s = residual_samples(m, c);
  std::vector<AxisResidual> out;
  if (s.empty()) return out;
  double total_weight = 0, mean = 0, variance = 0;
  for (const auto& q : s) total_weight += q.weight, mean += q.weight * q.r_over_g;
  mean /= total_weight;
  for (const auto& q : s) variance += q.weight * (q.r_over_g - mean) * (q.r_over_g - mean);
  for (int a = 0; a < kAxes; ++a) {
    AxisResidual ar;
    ar.axis = kAxisNames[a];
    bin_profile(s, a, total_weight, mean, variance, ar);
    if (a < kFirstTrialAxis) within_trial_slopes(s, c.trials.size(), a, ar);
    out.push_back(ar);
  }
  return out;
}

}  // namespace gravsweep::results

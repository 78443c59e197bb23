// Held-out errors: grouped K-fold cross-validation and its summary (see cross_validation.h), and
// the signed-rank tests over trials that compare held-out errors (model_internal.h).
#include "results/model/model_spec.h"
#include "results/model/fit.h"
#include "results/model/predict.h"
#include "results/model/cross_validation.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "results/model/model_internal.h"

namespace gravsweep::results {

namespace detail {

double binom_tail_half(int k, int n) {
  // P(X >= k), X ~ Binomial(n, 1/2)
  double p = 0;
  for (int i = k; i <= n; ++i)
    p += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) - n * std::log(2.0));
  return std::min(1.0, p);
}

bool cannot_tell_apart(const std::vector<double>& other_worse) {
  std::vector<double> other_better(other_worse.size());
  std::transform(other_worse.begin(), other_worse.end(), other_better.begin(), [](double x) { return -x; });
  return signed_rank_p(other_worse) >= kEquivalentLevel && signed_rank_p(other_better) >= kEquivalentLevel;
}

/// One-sided Wilcoxon signed-rank test that the per-trial improvements d_i are centred above 0:
/// one value per trial, so n is the number of trials (never samples). Normal approximation with
/// continuity correction (n >= 10 here); ties get average ranks.
double signed_rank_p(const std::vector<double>& d) {
  std::vector<std::pair<double, bool>> a;
  for (double x : d)
    if (x != 0.0 && std::isfinite(x)) a.push_back({std::abs(x), x > 0});
  const double n = static_cast<double>(a.size());
  if (a.size() < 5) return 1.0;
  std::sort(a.begin(), a.end());
  double wplus = 0;
  for (std::size_t i = 0; i < a.size();) {
    std::size_t j = i;
    while (j < a.size() && a[j].first == a[i].first) ++j;
    const double rank = 0.5 * (static_cast<double>(i + 1) + static_cast<double>(j));
    for (std::size_t k = i; k < j; ++k)
      if (a[k].second) wplus += rank;
    i = j;
  }
  const double mean = n * (n + 1) / 4, sd = std::sqrt(n * (n + 1) * (2 * n + 1) / 24);
  const double z = (wplus - mean - 0.5) / sd;
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}

std::vector<int> fold_of(const Campaign& c, int folds, unsigned seed) {
  if (folds == kLeaveOneProjectileOut) return projectile_index(c);
  // Stratified by gravity level: shuffle within each level, deal round-robin.
  std::mt19937 rng(seed);
  std::vector<int> idx(c.trials.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::vector<double> key(idx.size());
  for (auto& k : key) k = std::uniform_real_distribution<double>(0, 1)(rng);
  const std::vector<double> levels = c.gravity_levels();  // descending
  std::vector<int> level(idx.size(), 0);
  for (std::size_t i = 0; i < idx.size(); ++i)
    while (!same_gravity_level(levels[static_cast<std::size_t>(level[i])], c.trials[i].info.gravity_m_s2)) ++level[i];
  std::sort(idx.begin(), idx.end(),
            [&](int a, int b) { return level[a] != level[b] ? level[a] < level[b] : key[a] < key[b]; });
  std::vector<int> f(idx.size());
  for (std::size_t r = 0; r < idx.size(); ++r) f[idx[r]] = static_cast<int>(r % folds);
  return f;
}

}  // namespace detail

using namespace detail;

std::vector<int> projectile_index(const Campaign& c, int* count) {
  std::vector<std::pair<double, double>> seen;
  std::vector<int> index;
  for (const auto& t : c.trials) {
    const std::pair<double, double> p{t.info.projectile_diameter_m, t.info.projectile_mass_kg};
    const auto it = std::find_if(seen.begin(), seen.end(), [&p](const auto& q) {
      return std::abs(q.first - p.first) <= 1e-9 * q.first && std::abs(q.second - p.second) <= 1e-9 * q.second;
    });
    index.push_back(static_cast<int>(it - seen.begin()));
    if (it == seen.end()) seen.push_back(p);
  }
  if (count) *count = static_cast<int>(seen.size());
  return index;
}

HeldOut detail::over_folds(const Campaign& c, int folds, unsigned seed, const FoldFit& fit_fold) {
  HeldOut h;
  h.trace_mse.assign(c.trials.size(), NAN);
  h.pred.assign(c.trials.size(), Prediction{});
  const auto f = fold_of(c, folds, seed);
  // The folds are fitted in parallel, each writing only its held-out trials' entries.
  parallel_for_each_index(static_cast<std::size_t>(fold_count(f)), [&](std::size_t fold) {
    const int k = static_cast<int>(fold);
    std::vector<bool> train(c.trials.size());
    bool any = false;
    for (std::size_t i = 0; i < train.size(); ++i) {
      train[i] = f[i] != k;
      any = any || !train[i];
    }
    if (any) fit_fold(train, h);
  });
  return h;
}

HeldOut cross_validate(const ModelSpec& spec, const Campaign& c, int folds, unsigned seed, bool with_predictions) {
  return over_folds(c, folds, seed, [&](const std::vector<bool>& train, HeldOut& h) {
    const FittedModel m = fit_model(spec, c, train);
    // The training trials' fluctuations about the model, for apeak as measured (predict.h).
    std::vector<std::vector<double>> fluct(with_predictions ? c.trials.size() : 0);
    for (std::size_t j = 0; j < fluct.size(); ++j)
      if (train[j]) fluct[j] = relative_residuals(m, c.trials[j]);
    for (std::size_t i = 0; i < train.size(); ++i) {
      if (train[i]) continue;
      h.trace_mse[i] = trial_trace_mse(m, c.trials[i]);
      if (with_predictions) h.pred[i] = predict(m, c.trials[i], same_level_fluctuations(c, fluct, i));
    }
  });
}

HeldOut cross_validate(const ModelSpec& spec, const Campaign& c, int folds, unsigned seed) {
  return cross_validate(spec, c, folds, seed, true);
}

ErrorSummary summarize(const Campaign& c, const HeldOut& h) {
  ErrorSummary e;
  double st = 0, str = 0, sz = 0, szr = 0, stt = 0, sttr = 0, sa = 0, sar = 0;
  int nt = 0, nz = 0, ntt = 0, na = 0;
  for (std::size_t i = 0; i < c.trials.size(); ++i) {
    const auto& t = c.trials[i];
    const auto& m = t.processed.metrics;
    if (std::isfinite(h.trace_mse[i])) {
      double ref = 0;
      std::size_t n = 0;
      for (std::size_t k = t.fit_begin; k < t.fit_end; ++k, ++n)
        ref += std::pow(t.processed.accel_up_m_s2[k] + t.info.gravity_m_s2, 2);
      st += h.trace_mse[i];
      if (n && ref > 0) str += h.trace_mse[i] / (ref / static_cast<double>(n));
      ++nt;
    }
    const auto& p = h.pred[i];
    if (!p.stopped) continue;
    // A clipped record's apeak (a lower bound), and its zstop when the clip moved it, are no
    // measurement to hold a prediction against (clip_exclusion).
    if (clip_exclusion(t, ClippedMetric::zstop).empty()) {
      sz += std::pow(1e3 * (p.zstop_m - m.zstop_m), 2);
      szr += std::pow((p.zstop_m - m.zstop_m) / m.zstop_m, 2);
      ++nz;
    }
    stt += std::pow(1e3 * (p.tstop_s - m.tstop_s), 2);
    sttr += std::pow((p.tstop_s - m.tstop_s) / m.tstop_s, 2);
    ++ntt;
    if (clip_exclusion(t, ClippedMetric::apeak).empty()) {
      sa += std::pow(p.apeak_m_s2 - m.apeak_m_s2, 2);
      sar += std::pow((p.apeak_m_s2 - m.apeak_m_s2) / m.apeak_m_s2, 2);
      ++na;
    }
  }
  e.trials = nt;
  if (nt) {
    e.trace_rms_m_s2 = std::sqrt(st / nt);
    e.trace_rel_pct = 100 * std::sqrt(str / nt);
  }
  auto rms = [](double s, int n) { return n ? std::sqrt(s / n) : NAN; };
  e.zstop_rms_mm = rms(sz, nz);
  e.zstop_rel_pct = 100 * rms(szr, nz);
  e.tstop_rms_ms = rms(stt, ntt);
  e.tstop_rel_pct = 100 * rms(sttr, ntt);
  e.apeak_rms_m_s2 = rms(sa, na);
  e.apeak_rel_pct = 100 * rms(sar, na);
  return e;
}

}  // namespace gravsweep::results

// The search beyond the named library (model_internal.h): a forward step over the
// generated family (generated.h) judged by nested grouped cross-validation, so that choosing one
// form out of many is itself what the held-out test judges.
#include <algorithm>
#include <cmath>
#include <limits>

#include "results/model/generated.h"
#include "results/model/cross_validation.h"
#include "results/model/discover.h"
#include "results/model/fit.h"
#include "results/model/model_spec.h"
#include "results/model/model_internal.h"

namespace gravsweep::results::detail {

namespace {

/// Per-trial in-sample trace MSE of the selected trials (NaN for the others).
std::vector<double> trial_mses(const FittedModel& m, const Campaign& c, const std::vector<bool>& mask) {
  std::vector<double> e(c.trials.size(), NAN);
  for (std::size_t i = 0; i < c.trials.size(); ++i)
    if (mask[i]) e[i] = trial_trace_mse(m, c.trials[i]);
  return e;
}

/// Mean over trials of (before - after) / before: the criterion the held-out test uses.
double mean_relative_gain(const std::vector<double>& before, const std::vector<double>& after) {
  double s = 0;
  int n = 0;
  for (std::size_t i = 0; i < before.size(); ++i) {
    if (!std::isfinite(before[i]) || !std::isfinite(after[i]) || before[i] <= 0) continue;
    s += (before[i] - after[i]) / before[i];
    ++n;
  }
  return n ? s / n : 0;
}

struct Screened {
  const TermInfo* term = nullptr;
  double gain = 0;          ///< in-sample mean relative gain over `current`
  std::vector<double> mse;  ///< per-trial in-sample trace MSE with the form
};

/// `current` fitted to the selected trials, and every form of the family added to it (per gravity
/// level) and fitted to the same trials, best (largest in-sample mean relative gain) first.
struct Screening {
  FittedModel current;
  std::vector<double> current_mse;  ///< per-trial in-sample trace MSE of `current`
  std::vector<Screened> ranked;
};
/// The forms are fitted in parallel (parallel_for_each_index), each into its own slot.
Screening screen(const ModelSpec& current, const Campaign& c, const std::vector<bool>& mask, bool per_gravity = true) {
  Screening out{fit_model(current, c, mask), {}, {}};
  out.current_mse = trial_mses(out.current, c, mask);
  std::vector<const TermInfo*> forms;
  for (const auto& name : generated_family())
    if (!current.has(name)) forms.push_back(generated_term(name));
  out.ranked.resize(forms.size());
  parallel_for_each_index(forms.size(), [&](std::size_t j) {
    ModelSpec s = current;
    s.terms.push_back({forms[j], per_gravity, 1.0});
    auto mse = trial_mses(fit_model(s, c, mask), c, mask);
    out.ranked[j] = {forms[j], mean_relative_gain(out.current_mse, mse), std::move(mse)};
  });
  std::stable_sort(out.ranked.begin(), out.ranked.end(),
                   [](const Screened& a, const Screened& b) { return a.gain > b.gain; });
  return out;
}

/// The forms the trials cannot tell apart from the best one (cannot_tell_apart, on the per-trial MSE
/// difference relative to `current`'s). Each has one parameter per level, so in-sample fits
/// compare them fairly.
std::vector<std::string> equivalent_forms(const std::vector<Screened>& ranked, const std::vector<double>& before) {
  std::vector<std::string> out;
  for (std::size_t j = 1; j < ranked.size(); ++j) {
    std::vector<double> worse;
    for (std::size_t i = 0; i < before.size(); ++i)
      if (std::isfinite(before[i]) && before[i] > 0 && std::isfinite(ranked[j].mse[i]) &&
          std::isfinite(ranked[0].mse[i]))
        worse.push_back((ranked[j].mse[i] - ranked[0].mse[i]) / before[i]);
    if (cannot_tell_apart(worse)) out.push_back(ranked[j].term->name);
  }
  return out;
}

}  // namespace

const TermInfo* best_generated_form(const ModelSpec& current, const Campaign& c, bool per_gravity) {
  const Screening s = screen(current, c, std::vector<bool>(c.trials.size(), true), per_gravity);
  return s.ranked.empty() || !(s.ranked.front().gain > 0) ? nullptr : s.ranked.front().term;
}

GeneratedSearch search_generated(const ModelSpec& current, const Campaign& c, int folds, double alpha,
                                 double min_improvement) {
  GeneratedSearch g;
  const std::size_t n = c.trials.size();
  const std::vector<bool> all(n, true);
  const Screening on_all = screen(current, c, all);
  const auto& ranked = on_all.ranked;
  if (ranked.empty()) return g;
  g.equivalent = equivalent_forms(ranked, on_all.current_mse);
  // The form, on all trials; shared by the gravity levels when that is as good held out.
  ModelTerm chosen{ranked.front().term, true, 1.0};
  if (on_all.current.gravity_levels.size() > 1) {
    ModelSpec per = current, shared = current;
    per.terms.push_back(chosen);
    shared.terms.push_back({chosen.term, false, 1.0});
    auto mean_of = [&](const HeldOut& h) {
      double s = 0;
      for (double e : h.trace_mse) s += std::isfinite(e) ? e : 0;
      return s;
    };
    if (mean_of(cross_validate(shared, c, folds, 1, false)) <= mean_of(cross_validate(per, c, folds, 1, false)))
      chosen.per_gravity = false;
  }
  g.chosen = chosen;
  // Nested CV: in each fold the form is chosen on the training trials alone, then judged on the
  // held-out ones against the current model fitted to the same training trials.
  const auto fold = fold_of(c, folds, 1);
  std::vector<double> mse0(n, NAN), mse1(n, NAN);
  for (int k = 0; k < fold_count(fold); ++k) {
    std::vector<bool> train(n);
    bool any = false;
    for (std::size_t i = 0; i < n; ++i) {
      train[i] = fold[i] != k;
      any = any || fold[i] == k;
    }
    if (!any) continue;
    const Screening on_train = screen(current, c, train);
    ModelSpec with = current;
    with.terms.push_back({on_train.ranked.front().term, chosen.per_gravity, 1.0});
    const FittedModel m1 = fit_model(with, c, train);
    for (std::size_t i = 0; i < n; ++i)
      if (!train[i])
        mse0[i] = trial_trace_mse(on_train.current, c.trials[i]), mse1[i] = trial_trace_mse(m1, c.trials[i]);
  }
  Candidate& cd = g.test;
  cd.term = chosen.term->name + (chosen.per_gravity ? "" : ":shared");
  std::vector<double> rel;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(mse0[i]) || !std::isfinite(mse1[i]) || mse0[i] <= 0) continue;
    rel.push_back((mse0[i] - mse1[i]) / mse0[i]);
    cd.trials_better += rel.back() > 0;
  }
  cd.trials = static_cast<int>(rel.size());
  for (double r : rel) cd.mean_rel_improvement += r / std::max(1, cd.trials);
  cd.p_value = signed_rank_p(rel);
  cd.significant = cd.p_value < alpha && cd.mean_rel_improvement >= min_improvement;
  // The screening on all trials, for the table: in-sample relative improvement, no test of its own.
  for (const auto& s : ranked) {
    Candidate r;
    r.term = s.term->name;
    r.mean_rel_improvement = s.gain;
    r.p_value = NAN;
    g.screened.push_back(r);
  }
  return g;
}

}  // namespace gravsweep::results::detail

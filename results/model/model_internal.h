// Helpers shared by the files of results/model/ (fit.cpp, cross_validation.cpp, table3.cpp,
// discover.cpp, ...); not API.
#pragma once
#include <cstddef>
#include <exception>
#include <functional>
#include <vector>

#include "results/model/model_spec.h"
#include "results/model/fit.h"
#include "results/measurements/campaign.h"
#include "results/model/cross_validation.h"
#include "results/model/discover.h"
#include "results/model/predict.h"
#include "results/model/term.h"

namespace gravsweep::results::detail {

/// body(i) for every i in [0, n), on OpenMP threads (dynamic, one index at a time): for loops
/// whose iterations write only their own slots, so the result is the same on any thread count. An
/// exception may not leave an OpenMP region: the lowest index's is rethrown after the loop.
template <class Body>
void parallel_for_each_index(std::size_t n, Body&& body) {
  std::vector<std::exception_ptr> failed(n);
  const auto count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for schedule(dynamic, 1)
  for (std::ptrdiff_t k = 0; k < count; ++k) {
    try {
      body(static_cast<std::size_t>(k));
    } catch (...) {
      failed[static_cast<std::size_t>(k)] = std::current_exception();
    }
  }
  for (const auto& e : failed)
    if (e) std::rethrow_exception(e);
}

/// The state of trial t at sample k.
TermContext context(const MeasuredTrial& t, std::size_t k);
/// The state at first contact (impact speed, no depth).
TermContext context(const Trial& i);
/// Called at the start of each step of the integrated motion (predict): time since contact, depth
/// and downward speed there, and the step's length (the last step ends at the stop).
using MotionVisitor = std::function<void(double t_s, double z_m, double v_m_s, double dt_s)>;
/// predict(m, c0, t_max_s), calling `visit` (when set) at every step.
Prediction integrate_motion(const FittedModel& m, const TermContext& c0, double t_max_s, const MotionVisitor& visit);
/// P(X >= k), X ~ Binomial(n, 1/2).
double binom_tail_half(int k, int n);
/// One-sided Wilcoxon signed-rank p-value that the per-trial values are centred above 0.
double signed_rank_p(const std::vector<double>& d);
/// Two explanations the trials cannot tell apart: given per trial how much worse the second fits
/// than the first (a difference of relative held-out errors), neither one-sided signed-rank test
/// (that it is worse, that it is better) falls below kEquivalentLevel.
inline constexpr double kEquivalentLevel = 0.05;
bool cannot_tell_apart(const std::vector<double>& other_worse);
/// Fold of each trial, stratified by gravity level (same_gravity_level); with folds =
/// kLeaveOneProjectileOut, the index of the trial's projectile (distinct diameter and mass, in
/// order of first appearance).
std::vector<int> fold_of(const Campaign& c, int folds, unsigned seed);
/// How many folds a fold_of assignment has.
inline int fold_count(const std::vector<int>& f) {
  int n = 0;
  for (const int k : f) n = k + 1 > n ? k + 1 : n;
  return n;
}
/// Fits on one fold's training trials (`train`) and fills the held-out trials' entries of `h`,
/// and no other: the folds run on parallel threads, each on its own entries of the same `h`.
using FoldFit = std::function<void(const std::vector<bool>& train, HeldOut& h)>;
/// The loop of every grouped K-fold cross-validation (fold_of): `fit_fold` once per fold that
/// holds a trial out, on a HeldOut sized to the campaign's trials (NaN until filled); the folds
/// in parallel (OpenMP, as many threads as cores), the result independent of the thread count.
HeldOut over_folds(const Campaign& c, int folds, unsigned seed, const FoldFit& fit_fold);

/// One forward step over the generated family (search_generated.cpp). The form is the one that,
/// added per gravity level to `current`, fits all trials best (shared instead when that is as good
/// held out); `test` judges the whole procedure by nested grouped CV (in each fold the form is
/// chosen on the training trials alone), so one signed-rank test at level alpha covers the choice
/// among all forms; `screened` lists every form by its in-sample improvement (no test, p NaN).
struct GeneratedSearch {
  ModelTerm chosen;
  Candidate test;
  std::vector<Candidate> screened;
  std::vector<std::string> equivalent;  ///< forms the trials cannot tell apart from the chosen one
};
/// The form of the generated family that, added to `current` (one parameter per gravity level, or
/// one for all levels when per_gravity is false), fits all trials best in sample; nullptr when
/// none improves on `current`. Chosen in sample, so a held-out test of it alone is optimistic.
const TermInfo* best_generated_form(const ModelSpec& current, const Campaign& c, bool per_gravity);
GeneratedSearch search_generated(const ModelSpec& current, const Campaign& c, int folds, double alpha,
                                 double min_improvement);

}  // namespace gravsweep::results::detail

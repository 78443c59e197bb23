// "Which effect is missing": forward selection over the registered terms by held-out improvement
// (signed-rank test over trials), then the generated family (generated.h) when structure is left
// (docs/physics/force-laws.md section 2.4).
#pragma once
#include <string>
#include <vector>

#include "results/model/model_spec.h"
#include "results/measurements/campaign.h"
#include "results/model/cross_validation.h"
#include "results/model/residual_axes.h"

namespace gravsweep::results {

/// One candidate's held-out improvement over the current model.
struct Candidate {
  std::string term;                 ///< as a model spec names it: "depth_friction:shared", "immersion_drag:g^1"
  ModelTerm form;                   ///< the term as it was tried (its sharing)
  double mean_rel_improvement = 0;  ///< mean over trials of (mse0 - mse1) / mse0
  int trials_better = 0, trials = 0;
  double p_value = 1;  ///< one-sided Wilcoxon signed-rank test over trials (not samples)
  bool significant = false;
  std::vector<double> trial_rel_gain;  ///< (mse0 - mse1) / mse0 per trial of the campaign, NaN where not finite
};
struct Discovery {
  std::string baseline;
  /// The baseline has no parameter per gravity level (one law for all levels): only such terms
  /// are candidates (scaled mode, `model rank --scaled`).
  bool gravity_scaled = false;
  std::vector<std::vector<Candidate>> rounds;  ///< ranking of the named terms per forward step
  std::vector<std::string> added;              ///< named winners, in order, as a model spec names them
  std::string named_model;                     ///< the baseline with the named winners (parse_model reads it)
  /// Per named winner, the other significant terms of its round that the held-out trials cannot
  /// tell apart from it (detail::cannot_tell_apart): the verdict names them beside it. The best
  /// form of the generated family added to the same model is judged the same way and, when the
  /// trials cannot tell it from the winner, listed as "c * <form>".
  std::vector<std::vector<std::string>> equivalent;
  std::string verdict;          ///< the sentence for users
  bool structure_left = false;  ///< residuals structured after the named additions
  /// A trend too weak for the binned tests (eta^2) but the same in almost every trial (sign test
  /// over trials p < kConsistentTrendP), described ("along depth_m: 41 of 42 trials ..."); empty
  /// when there is none. It also starts the search beyond the named library.
  std::string consistent_trend;
  std::vector<AxisResidual> residual_before, residual_after;
  /// The search beyond the named library (generated.h), run when the named terms were added or
  /// left structure: the nested-CV test of choosing a form (its `term` is the form chosen on all
  /// trials), every form by in-sample improvement, the form added (empty when the test is not
  /// significant), the model with it, whether structure is still left with it, and the held-out
  /// errors without and with it.
  bool generated_searched = false;
  Candidate generated_test;
  std::vector<Candidate> generated_screened;
  std::string generated;
  std::vector<std::string> generated_equivalent;  ///< forms the trials cannot tell apart from it
  bool generated_worsens_metrics = false;         ///< significant on the trace, but zstop or tstop worse held out
  std::string generated_model;
  bool structure_left_after_generated = false;
  ErrorSummary errors_without_generated, errors_with_generated;
};
/// A within-trial residual slope of the same sign in this many trials (sign test p below it) is a
/// trend, however small its share of the residual variance (eta^2): DEM traces carry force-chain
/// noise that keeps eta^2 low while the trend holds in 41 of 42 trials (the full Chrono
/// campaign).
inline constexpr double kConsistentTrendP = 1e-6;

/// Forward selection from `baseline` over all other registered terms by grouped-CV improvement,
/// adding a term while one is significant (signed-rank test over trials, Bonferroni over candidates, at
/// level alpha, and at least min_improvement mean relative gain). When a named term was added or
/// the residuals are still structured (the tests of residual_axes) or trend consistently
/// (kConsistentTrendP), one more step runs over the
/// generated family (model_internal.h, search_generated: nested grouped CV, one signed-rank test at
/// level alpha), and a significant form is reported by its formula: the residuals of the named
/// winners are tested again, and structure they leave makes the verdict "partly explained".
Discovery discover(const Campaign& c, const ModelSpec& baseline, int folds = 6, double alpha = 0.01,
                   double min_improvement = 0.03, int max_rounds = 2, bool search_generated = true);

}  // namespace gravsweep::results

// Leave one gravity level out: one law for all levels (one_law_for_all_levels, e.g. scaled_base:
// R = phi m g + m v^2 / d1) is fitted on the trials of every other level and predicts zstop, tstop
// and apeak of each trial of the level left out, the way they were measured (predict, predict.h).
// A law whose gravity dependence is right predicts a level it has never seen as well as the
// levels it was fitted on; a resistance that does not follow g shows as errors at the held-out
// levels. Targets (median |error| over the drops of a level inside the fitted range of g):
// zstop within kLevelOutZstopTargetPct, tstop within kLevelOutTstopTargetPct.
#pragma once
#include <cmath>
#include <string>
#include <vector>

#include "results/measurements/campaign.h"
#include "results/model/fit.h"
#include "results/model/model_spec.h"
#include "results/model/predict.h"

namespace gravsweep::results {

inline constexpr double kLevelOutZstopTargetPct = 10.0;
inline constexpr double kLevelOutTstopTargetPct = 15.0;

/// One trial of the held-out level.
struct LevelOutTrial {
  std::size_t trial = 0;       ///< index in the campaign
  double impact_froude = NAN;  ///< vc / sqrt(g D), D the projectile diameter
  Prediction pred;
  /// 100 (predicted - measured) / measured; NaN when the law's motion did not stop, or the
  /// measurement is left out (a clipped record: clip_exclusion).
  double zstop_err_pct = NAN, tstop_err_pct = NAN, apeak_err_pct = NAN;
};

/// The held-out drops of one Froude number of the design (impact Fr within 5 % in ln Fr): the
/// signed mean errors, which a median over the level hides (a law that under-predicts every Fr 10
/// drop by 20 % passes a median over six Froude numbers).
struct LevelOutFroude {
  double froude = NAN;  ///< mean impact Fr of the drops
  int drops = 0;
  double zstop_mean_err_pct = NAN, tstop_mean_err_pct = NAN;  ///< signed: predicted - measured
  double zstop_min_err_pct = NAN, zstop_max_err_pct = NAN;
  bool misses = false;  ///< |zstop mean| > kLevelOutZstopTargetPct or |tstop mean| > kLevelOutTstopTargetPct
};

/// One held-out gravity level.
struct LevelOutRow {
  double g_m_s2 = 0;
  int trials = 0;
  std::vector<double> fitted_g_m_s2;  ///< the other levels, the law's training set (descending)
  bool inside = false;                ///< g within the range of the fitted levels (else an extrapolation)
  FittedModel law;                    ///< fitted on the other levels
  /// The law's quasi-static / inertial crossover at this level (surface_crossover_froude): the
  /// verdict says in which regime a miss lies.
  double crossover_froude = NAN;
  double zstop_median_abs_err_pct = NAN, tstop_median_abs_err_pct = NAN, apeak_median_abs_err_pct = NAN;
  /// The same law fitted on every level, this one included: its median |error| here tells a law
  /// whose form misses this level (large either way) from one whose gravity scaling does (small
  /// only when the level is in the fit).
  double zstop_all_levels_median_abs_err_pct = NAN, tstop_all_levels_median_abs_err_pct = NAN;
  /// The law's own uncertainty here: per drop, the standard deviation of its predicted zstop and
  /// tstop (% of the prediction) propagated from the cluster-robust covariance of its constants
  /// (delta method); the median over the drops. A miss by less than twice this is the fit's noise.
  double zstop_law_sd_pct = NAN, tstop_law_sd_pct = NAN;
  std::vector<LevelOutTrial> per_trial;
  std::vector<LevelOutFroude> by_froude;  ///< ascending Fr
  std::string verdict;
};

/// One row per gravity level of the campaign (descending g). apeak as measured, with the training
/// trials' fluctuations about the law (nearest levels first: the held-out level has none in the
/// fit). Throws std::invalid_argument when the law has a parameter per gravity level or the
/// campaign has fewer than two levels.
std::vector<LevelOutRow> leave_level_out(const ModelSpec& law, const Campaign& c);

/// The median of |x| over the finite values (NaN when there are none).
double median_abs(const std::vector<double>& x);

/// Trial t's prediction p with its signed errors (predicted - measured, % of measured; NaN where
/// the law's motion did not stop or a clipped record leaves the metric out) and impact Fr.
LevelOutTrial signed_errors(const MeasuredTrial& t, const Prediction& p);
/// The drops grouped by the design's Froude number (froude_groups), with their signed mean
/// errors, ascending Fr.
std::vector<LevelOutFroude> by_froude(const std::vector<LevelOutTrial>& per_trial);

/// One cell of a campaign's design: a gravity level and a Froude number.
struct FroudeCell {
  double g_m_s2 = 0;
  LevelOutFroude errors;
};
/// Every trial's prediction `pred` (one per trial; held out, from cross_validate) by gravity level
/// (descending) and Froude number: the signed mean errors a median over all trials hides.
std::vector<FroudeCell> froude_cells(const Campaign& c, const std::vector<Prediction>& pred);

}  // namespace gravsweep::results

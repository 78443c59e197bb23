// A model fitted to a campaign's traces: least squares on m (a_up + g) = R(z, v) over each
// collision, trials weighted equally, covariance cluster-robust over trials
// (docs/physics/force-laws.md section 2.5).
#pragma once
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "results/measurements/campaign.h"
#include "results/model/model_spec.h"

namespace gravsweep::results {

/// A model with fitted coefficients for the gravity levels of a campaign.
struct FittedModel {
  ModelSpec spec;
  std::vector<double> gravity_levels;
  std::vector<std::string> column_names;  ///< "base.f0_N@g=9.81"
  Eigen::VectorXd coef;
  Eigen::MatrixXd cov;  ///< cluster-robust (trials as clusters)
  int trials_used = 0;
  std::size_t samples_used = 0;
  /// Resisting force R (N) at a state; throws std::invalid_argument at a gravity level the model
  /// was not fitted on, unless it is one law for all levels (one_law_for_all_levels).
  [[nodiscard]] double force(const TermContext& c) const;
  [[nodiscard]] int gravity_index(double g) const;  ///< -1 when unknown
};

/// Fits the spec to the trials' fit windows (each trial weighted equally), least squares on
/// m (a_up + g) = R(z, v), residuals in units of m g; for one law for all levels
/// (one_law_for_all_levels) in units of each trial's RMS force instead, as its trials span
/// Froude numbers 0.2-10 and forces 1-300 m g. `trial_mask` (same length as campaign.trials)
/// selects training trials.
FittedModel fit_model(const ModelSpec& spec, const Campaign& c, const std::vector<bool>& trial_mask);
FittedModel fit_model(const ModelSpec& spec, const Campaign& c);
/// The same with each trial counted `trial_count[i]` times (0: left out): a bootstrap resample
/// of whole trials.
FittedModel fit_model(const ModelSpec& spec, const Campaign& c, const std::vector<int>& trial_count);

/// Mean squared acceleration residual (m/s2)^2 of a trial's fit window (a_meas - a_model).
double trial_trace_mse(const FittedModel& m, const MeasuredTrial& t);

}  // namespace gravsweep::results

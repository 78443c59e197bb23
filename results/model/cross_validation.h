// Held-out errors: grouped K-fold cross-validation over whole trials (or one fold per projectile),
// and their summary against the measured metrics (docs/physics/force-laws.md section 2.5).
#pragma once
#include <vector>

#include "results/measurements/campaign.h"
#include "results/model/model_spec.h"
#include "results/model/predict.h"

namespace gravsweep::results {

/// Per-trial held-out results of grouped K-fold cross-validation (whole trials held out); apeak
/// as measured with the training trials' fluctuations at the trial's level.
struct HeldOut {
  std::vector<double> trace_mse;  ///< per trial
  std::vector<Prediction> pred;   ///< per trial, from the model fitted without that trial
};
/// The projectile of each trial: the index of its (diameter, mass), distinct to 1e-9 relative, in
/// order of first appearance; `count` receives how many there are.
std::vector<int> projectile_index(const Campaign& c, int* count = nullptr);
/// `folds` = kLeaveOneProjectileOut: one fold per projectile (its diameter and mass), so that each
/// projectile is predicted by the model fitted on the others.
inline constexpr int kLeaveOneProjectileOut = -1;
HeldOut cross_validate(const ModelSpec& spec, const Campaign& c, int folds = 6, unsigned seed = 1);
/// The same; without predictions (trace residuals only) when with_predictions is false.
HeldOut cross_validate(const ModelSpec& spec, const Campaign& c, int folds, unsigned seed, bool with_predictions);

/// Summary errors against the measured metrics (RMS over trials; relative in %).
struct ErrorSummary {
  double trace_rms_m_s2 = 0, trace_rel_pct = 0;
  double zstop_rms_mm = 0, zstop_rel_pct = 0;
  double tstop_rms_ms = 0, tstop_rel_pct = 0;
  double apeak_rms_m_s2 = 0, apeak_rel_pct = 0;
  int trials = 0;
};
ErrorSummary summarize(const Campaign& c, const HeldOut& h);

}  // namespace gravsweep::results

// A fitted model's motion: Eq. 1 of Sunday et al. 2021 integrated from the impact to the stop, the
// metrics it predicts (zstop, tstop, apeak), and the model's record of a measured trial.
#pragma once
#include <cmath>
#include <cstddef>
#include <vector>

#include "results/measurements/campaign.h"
#include "results/model/fit.h"

namespace gravsweep::results {

struct Prediction {
  double zstop_m = NAN, tstop_s = NAN, apeak_m_s2 = NAN;
  bool stopped = false;
};
/// How long predict integrates before it gives up on a stop (s): kPredictHorizonScaled collision
/// time scales sqrt(D/g) (D the projectile diameter; a drop at 0.001 m/s2 lasts 10 s and more),
/// and at least kPredictHorizonMin_s (the lab's 1 g collisions last well under a second).
inline constexpr double kPredictHorizonScaled = 50.0;
inline constexpr double kPredictHorizonMin_s = 10.0;
double prediction_horizon_s(const TermContext& trial);
/// Integrates m dv/dt = m g - R from the trial's impact speed (RK4) to the stop; apeak is the
/// largest deceleration of the integrated motion. t_max_s NaN: prediction_horizon_s.
Prediction predict(const FittedModel& m, const Trial& info);
Prediction predict(const FittedModel& m, const TermContext& trial, double t_max_s = NAN);
/// The metrics of a measured trial predicted the way it was measured: zstop and tstop
/// of the integrated motion, apeak read off the model's record (model_record) processed like the
/// trial (process_trial's options), so that the 500 Hz filter rounds both peaks alike.
Prediction predict(const FittedModel& m, const MeasuredTrial& t);
/// The same with the grain-scale fluctuation of other trials about the model (relative_residuals):
/// the measured apeak is the largest value of a fluctuating record (on synth campaigns 20 % of the
/// force, so 1.3-2 times the smooth peak), which the smooth model record never reaches; with the
/// fluctuations the model's record has the same kind of largest value. apeak is the mean of what
/// is read off the model's record with each sequence (of at least kMinFluctuationSamples) laid
/// over its collision, times the model's force per mass.
inline constexpr std::size_t kMinFluctuationSamples = 10;
Prediction predict(const FittedModel& m, const MeasuredTrial& t, const std::vector<const std::vector<double>*>& fluct);
/// A trial's fluctuation about the model over its fit window: (a_meas - a_model) / (R / m),
/// clamped to [-1, 1] (samples where the model's force is not positive are left out).
std::vector<double> relative_residuals(const FittedModel& m, const MeasuredTrial& t);
/// The model's record of a trial: on the trial's sample grid, free fall before the measured
/// collision start, Eq. 1 from the measured vc after it, rest after the model's stop; the trial's
/// source, and own velocity and depth when the trial's record has them (DEM).
Trace model_record(const FittedModel& m, const MeasuredTrial& t);

/// Up to kMaxFluctuationTrials of the sequences in `fluct` (one per trial of c, empty for those
/// not to use) from trials at trial i's gravity level other than i itself, in trial order.
inline constexpr std::size_t kMaxFluctuationTrials = 12;
std::vector<const std::vector<double>*> same_level_fluctuations(const Campaign& c,
                                                                const std::vector<std::vector<double>>& fluct,
                                                                std::size_t i);

}  // namespace gravsweep::results

// Where a fitted model fails: its residuals binned along depth, speed, time, gravity, impact speed
// and fill height, with the share of variance each binning explains and a sign test over trials.
#pragma once
#include <string>
#include <vector>

#include "results/measurements/campaign.h"
#include "results/model/fit.h"

namespace gravsweep::results {

/// Residuals along one axis: bins (quantiles) with the trial-weighted mean residual / g, and the
/// fraction of the residual variance the binning explains (eta^2).
struct AxisResidual {
  std::string axis;  ///< "depth_m", "speed_m_s", "time_since_contact_s", "gravity_m_s2", ...
  std::vector<double> bin_center, bin_mean_r_over_g;
  double eta2 = 0;
  double slope_sign_trials_p = 1;  ///< sign test over trials of the within-trial slope
  int trials_positive = 0, trials_negative = 0;
  double split_half_r = 0;  ///< bin profile of even- vs odd-numbered trials (Pearson r)
};
std::vector<AxisResidual> residual_axes(const FittedModel& m, const Campaign& c);

}  // namespace gravsweep::results

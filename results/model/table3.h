// The paper's method (Sunday et al. 2021 Sect. 4, Table 3): Eq. 2 fitted per gravity level to
// apeak(vc), Eqs. 3-4 for zstop and tstop, Eq. 5 for vt, and zstop ~ H^alpha.
#pragma once
#include <cmath>
#include <string>
#include <vector>

#include "results/model/predict.h"
#include "results/measurements/campaign.h"
#include "results/model/cross_validation.h"

namespace gravsweep::results {

/// The paper's method (Sect. 4): per gravity level, Eq. 2 fitted to apeak(vc), Eqs. 3-4 predict
/// zstop and tstop, Eq. 5 gives vt, and zstop ~ H^alpha with H = drop height + zstop.
struct Table3Row {
  double g_m_s2 = 0;
  int trials = 0;
  double f0_N = NAN, f0_se_N = NAN, inv_d1_1_m = NAN, inv_d1_se_1_m = NAN, vt_m_s = NAN, vt_se_m_s = NAN;
  double alpha = NAN, alpha_se = NAN;
  /// Bootstrap over whole drops (kTable3BootstrapResamples, fixed seed): uncertainties that
  /// include the scatter between impact sites, which the OLS errors above understate when sites repeat.
  double f0_boot_se_N = NAN, inv_d1_boot_se_1_m = NAN;
  std::string note;  ///< why a level was not fitted (too few trials or speeds), and clipped trials left out; else empty
};
inline constexpr int kTable3BootstrapResamples = 2000;
inline constexpr unsigned kTable3BootstrapSeed = 1;
/// Eq. 2 is a line in vc^2: a level is fitted only with at least kTable3MinTrials trials whose
/// collision speeds span at least a factor kTable3MinSpeedRatio (one speed cannot separate f0
/// from 1/d1).
inline constexpr int kTable3MinTrials = 3;
inline constexpr double kTable3MinSpeedRatio = 1.5;
std::vector<Table3Row> table3(const Campaign& c);
/// Eqs. 3-4 predictions for a trial from its gravity level's row (NaN when f0 <= m g).
Prediction predict_paper(const Table3Row& row, double mass_kg, double vc_m_s);
/// Held-out Eqs. 2-4 (Table 3 refitted without each fold).
HeldOut cross_validate_paper(const Campaign& c, int folds = 6, unsigned seed = 1);

}  // namespace gravsweep::results

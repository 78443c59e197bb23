// Froude-number collapse of a campaign across gravity levels (paper II, Sunday et al. 2022: depth
// and duration collapse when scaled by the Froude number). Each metric is scaled by the
// projectile's own scales, zstop / D, tstop sqrt(g / D) and apeak / g, against Fr = vc / sqrt(g D)
// (D the projectile diameter; v^2 / (g D) = Fr^2). How well it collapses is a number: the scatter
// of every drop about one common curve against the scatter of each level about its own curve.
#pragma once
#include <string>
#include <vector>

#include "results/measurements/campaign.h"

namespace gravsweep::results {

/// One scaled metric of one trial.
struct ScaledTrial {
  double gravity_m_s2 = 0;
  double froude = 0;  ///< vc / sqrt(g D)
  /// NaN (left out) for a clipped record's apeak and a zstop its clip moved (clip_exclusion).
  double zstop_over_D = 0, tstop_sqrt_g_over_D = 0, apeak_over_g = 0;
};
std::vector<ScaledTrial> scaled_trials(const Campaign& c);

/// How one scaled metric collapses. Curves are polynomials in ln Fr fitted to ln(metric)
/// (degree kCollapseDegree, lower for a level with fewer distinct Froude numbers); scatters are
/// RMS residuals of ln(metric), given as percentages (exp(s) - 1).
struct CollapseRow {
  std::string metric;  ///< "zstop_over_D", "tstop_sqrt_g_over_D", "apeak_over_g"
  int levels = 0, trials = 0;
  double common_scatter_pct = 0;  ///< every trial about one common curve
  double within_scatter_pct = 0;  ///< each level about its own curve (pooled): the repeat scatter
  /// The RMS difference between the levels' own curves where their Froude ranges overlap (NaN
  /// when no two levels overlap): how far apart the levels lie at equal Fr.
  double between_levels_pct = 0;
  /// common / within scatter (in ln units): 1 for a perfect collapse, larger when the levels
  /// lie apart.
  double collapse_ratio = 0;
  /// The level effect at equal Fr, by a nested analysis of variance of ln(metric) over the cells
  /// (Froude number of the design, level): repeats within a cell give the repeat variance, the cells'
  /// means about their Froude number's mean the level variance. Only Froude numbers run at two or
  /// more levels count. NaN where there are no such cells or no repeats.
  int cells = 0;                    ///< (Fr, level) cells at Froude numbers shared by two or more levels
  double level_scatter_pct = 0;     ///< the level's variance component, exp(sigma_L) - 1
  double repeat_scatter_pct = 0;    ///< the repeats' scatter within a cell, exp(sigma_r) - 1
  double level_f = 0, level_p = 0;  ///< F = MS_levels / MS_repeats and its upper-tail p
  int level_df = 0, repeat_df = 0;  ///< their degrees of freedom
};
inline constexpr int kCollapseDegree = 2;
/// Below this p the levels differ at equal Fr: the metric does not collapse.
inline constexpr double kLevelEffectP = 0.01;
std::vector<CollapseRow> collapse(const Campaign& c);

}  // namespace gravsweep::results

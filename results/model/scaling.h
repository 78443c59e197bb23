// The scaling check of a gravity-scaled law: which constant does not scale the way the law
// assumes. A law for all gravity levels (one_law_for_all_levels: scaled_base, shared terms) holds
// each of its constants the same at every level. The check frees one constant at a time (its
// value per gravity level, every other constant shared, the trials weighted as the law's fit
// weighs them), fits a power law c(g) = c0 (g / 9.81 m/s2)^p to the per-level values (weighted
// least squares on ln c, weights (c / se)^2) and takes the 95 % interval of p from a cluster
// bootstrap over drops (whole trials resampled within each level). A constant whose interval
// excludes 0 does not scale as assumed. Freed one at a time, such a constant drags the others
// along (they absorb part of its g-dependence), so the check runs in rounds: the most significant
// one (largest |p| / SE) is carried by its g^p and every constant is checked again against that
// law, until none differs. The verdict names the constants carried, each with its total power and
// interval, and the model to try instead ("scaled_base.inv_d1_1_m:g^0.2").
#pragma once
#include <string>
#include <vector>

#include "results/measurements/campaign.h"
#include "results/model/model_spec.h"

namespace gravsweep::results {

/// Bootstrap resamples of the power's interval (`model scaling --resamples`).
inline constexpr int kScalingResamples = 200;
/// The interval's coverage: 95 %.
inline constexpr double kScalingCoverage = 0.95;
/// Rounds of the check at most: each carries one more constant by its power of g (scaling_check).
inline constexpr int kScalingMaxRounds = 6;
/// The check needs this many gravity levels (a power law through two points has no scatter).
inline constexpr std::size_t kScalingMinLevels = 3;

struct ScalingRow {
  std::string constant;                               ///< "scaled_base.inv_d1_1_m": term.parameter
  double law_value = NAN;                             ///< the constant in the law, one value for all levels
  std::vector<double> gravity_m_s2, value, value_se;  ///< freed: per level (descending g), its SE
  /// The exponent of g of the freed values beyond what the law writes (0: scales as assumed), its
  /// bootstrap SE and 95 % interval; NaN when a level's value is not positive (note says which).
  double power = NAN, power_se = NAN, power_lo = NAN, power_hi = NAN;
  int resamples_used = 0;
  bool differs = false;  ///< the interval excludes 0
  std::string note;
};

struct ScalingCheck {
  std::string law;  ///< the law's name (ModelSpec::name)
  int trials = 0, levels = 0, resamples = 0;
  std::vector<ScalingRow> rows;      ///< one per constant of the law, from the last round, against the law as given
  std::vector<std::string> carried;  ///< the constants carried by a power of g, round by round
  std::string suggested_model;       ///< the law with each differing constant carried by g^p; empty: none
  /// When a constant differs and the levels reach different Froude numbers: that the power may be
  /// the law's form error along Fr, and the filter of the common range; else empty.
  std::string froude_note;
  std::string verdict;
};

/// The law with every term of several parameters split into one term per parameter
/// ("scaled_base" -> "scaled_base.phi", "scaled_base.inv_d1_1_m"), sharing and g-scaling kept.
ModelSpec split_parameters(const ModelSpec& law);

/// Runs the check on campaign `c` (at least kScalingMinLevels gravity levels); throws
/// std::invalid_argument when the law has a per-level term or the campaign too few levels.
ScalingCheck scaling_check(const ModelSpec& law, const Campaign& c, int resamples = kScalingResamples,
                           unsigned seed = 1);

}  // namespace gravsweep::results

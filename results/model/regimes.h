// The regime map of a fitted collision law (paper II, Sunday et al. 2022: a quasi-static friction
// regime below Fr ~ 1.5, an inertial-drag regime above). Along each drop's integrated motion
// (predict, predict.h) the resistance is split into its quasi-static part, what the bed resists with
// at rest at that depth, R(z, v = 0) (phi m g and any depth term), and its dynamic part,
// R(z, v) - R(z, 0) (the inertial drag m v^2 / d1 and any other speed-dependent term). Froude
// number Fr = v / sqrt(g D), D the projectile diameter. For R = phi m g + m v^2 / d1 the parts are
// equal at v^2 / d1 = phi g, i.e. Fr_c = sqrt(phi d1 / D) at every gravity level.
#pragma once
#include <cmath>
#include <vector>

#include "results/measurements/campaign.h"
#include "results/model/fit.h"

namespace gravsweep::results {

/// The resistance at a state split into its quasi-static and dynamic parts (N).
struct ResistanceSplit {
  double quasi_static_N = 0;
  double dynamic_N = 0;
};
ResistanceSplit split_resistance(const FittedModel& law, const TermContext& at);

/// Paper II's crossover from the quasi-static to the inertial regime (their Fr ~ 1.5).
inline constexpr double kPaperIICrossoverFroude = 1.5;

/// The Froude number at which the dynamic part equals the quasi-static one at the surface
/// (z = 0, at contact) for a projectile like `at` (its g, D, m): bisection in v up to
/// kCrossoverMaxFroude sqrt(g D), the dynamic part taken to grow with v. NaN when the quasi-static
/// part is not positive or the dynamic part never reaches it.
inline constexpr double kCrossoverMaxFroude = 100.0;
double surface_crossover_froude(const FittedModel& law, const TermContext& at);

/// One drop of the map: the law's motion from the measured impact speed to its stop.
struct RegimeTrial {
  std::size_t trial = 0;  ///< index in the campaign
  double g_m_s2 = 0, vc_m_s = 0;
  double impact_froude = NAN;  ///< vc / sqrt(g D)
  /// Shares (%) of the quasi-static part in the impulse (time integral) and in the work (depth
  /// integral) of the resistance over the motion; the dynamic part has the rest.
  double quasi_static_impulse_pct = NAN, quasi_static_work_pct = NAN;
  /// Where, along the motion, the dynamic part falls to the quasi-static one: Fr and depth there.
  /// NaN when the quasi-static part is the larger from the impact on (the drop starts in the
  /// quasi-static regime).
  double crossover_froude = NAN, crossover_depth_m = NAN;
  double surface_crossover_froude = NAN;  ///< of the law at this drop's g (surface_crossover_froude)
  bool stopped = false;                   ///< the law's motion came to rest
};
std::vector<RegimeTrial> regime_map(const FittedModel& law, const Campaign& c);

/// The impact Froude number at which the dynamic part carries half of a whole collision, by one
/// definition (its share of the impulse, or of the work): the drops grouped by the design's Froude
/// number (within 5 % in ln Fr), the groups' mean shares interpolated linearly in ln Fr to 50 %.
/// NaN where the shares never cross 50 %.
enum class CrossoverShare { impulse, work };
double whole_collision_crossover(const std::vector<RegimeTrial>& map, CrossoverShare share);
/// The same for the law fitted on the campaign, with its standard deviation propagated from the
/// cluster-robust covariance of the law's constants (central differences of 1 % of each constant,
/// delta method, as leave_level_out's prediction_sd).
struct CrossoverEstimate {
  double froude = NAN, sd = NAN;
};
CrossoverEstimate whole_collision_crossover(const FittedModel& law, const Campaign& c, CrossoverShare share);
/// surface_crossover_froude for a projectile like trial `at`'s, with its standard deviation
/// propagated the same way.
CrossoverEstimate surface_crossover(const FittedModel& law, const Trial& at);

}  // namespace gravsweep::results

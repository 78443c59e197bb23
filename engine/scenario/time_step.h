// The adaptive step of slow runs (schemas: /time_step for the drop, /bed/time_step for a bed's
// phases at its drop's gravity). A Hertz contact lasts longer as the speed falls (t_H ~ v^(-1/5):
// at 0.001 m/s2 and Froude number 1, 0.01 m/s, 2.6 times longer than at 1.2 m/s), so a slow,
// low-gravity run resolves its contacts with fewer steps.
#pragma once

#include "engine/system/system.h"

namespace gravsweep {

/// Before each interval the step becomes the shortest contact time of the pairs present at twice
/// the fastest particle's speed (an upper bound of any relative normal speed in the interval)
/// divided by steps_per_contact, never below the run's fixed step (the validated one) nor above
/// dt_max_s, and shortened so that a whole number of steps fills the interval (samples and checks
/// stay on their grid). The step depends only on the state, so a resumed run takes the same steps.
/// Resting contacts oscillate at a period set by their static overlap, which the speed does not
/// see: dt_max_s bounds the step for them (5e-5 s: more than 10 steps per period of a grain under
/// 20 layers of grains at 9.81 m/s2, more at lower gravity, where overlaps scale as (m g)^(2/3)).
struct AdaptiveStep {
  double steps_per_contact = 0;  ///< 0: off (the fixed step throughout)
  double dt_max_s = 0;           ///< cap on the step (must be >= the fixed step when on)
  [[nodiscard]] bool on() const { return steps_per_contact > 0; }
};

/// With the rule on: sets sys's step for the next interval_s (never below fixed_dt_s) and returns
/// the number of steps that fill it. Off: the fixed step, and interval_s / fixed_dt_s rounded.
long long choose_step(System& sys, const AdaptiveStep& rule, double fixed_dt_s, double interval_s);

/// Throws ConfigError naming `what` when the rule is on and dt_max_s < fixed_dt_s.
void check_adaptive_step(const AdaptiveStep& rule, double fixed_dt_s, const char* what);

}  // namespace gravsweep

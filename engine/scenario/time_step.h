// The adaptive step of slow runs (schemas: /time_step for the drop, /bed/time_step for a bed's
// phases at its drop's gravity). A Hertz contact lasts longer as the speed falls (t_H ~ v^(-1/5):
// at 0.001 m/s2 and Froude number 1, 0.01 m/s, 2.6 times longer than at 1.2 m/s), so a slow,
// low-gravity run resolves its contacts with fewer steps.
#pragma once

#include <string_view>

#include "engine/system/system.h"

namespace gravsweep {

/// Before each interval (of the order of a millisecond: a trace sample, a quench, a settling
/// check) the step target is the shortest contact time of the pairs present at the speed bound
/// (twice the fastest particle's speed, a bound of any relative normal speed over so short an
/// interval; or the largest normal approach speed of the pairs that can touch within it,
/// System::max_approach_speed_m_s, which a grain's sideways motion does not raise) divided by
/// steps_per_contact, clamped between the run's fixed step (the validated one) and dt_max_s; the
/// interval is then filled with the fewest whole steps no longer than the target (so a step may
/// come out a little below the fixed one; samples and checks stay on their grid). The step depends only on the state,
/// so a resumed run takes the same steps. Resting contacts oscillate at a period set by their static overlap, which the
/// speed does not see: dt_max_s bounds the step for them (5e-5 s: more than 10 steps per period of a grain under 20
/// layers of grains at 9.81 m/s2, more at lower gravity, where overlaps scale as (m g)^(2/3)).
struct AdaptiveStep {
  /// The relative normal speed at which the contact time is taken.
  enum class SpeedBound {
    fastest_particle,  ///< twice the fastest particle's speed (any pair's relative speed)
    normal_approach,   ///< System::max_approach_speed_m_s: the pairs present, each along its normal
  };
  double steps_per_contact = 0;  ///< 0: off (the fixed step throughout)
  double dt_max_s = 0;           ///< cap on the step (must be >= the fixed step when on)
  SpeedBound speed_bound = SpeedBound::fastest_particle;
  [[nodiscard]] bool on() const { return steps_per_contact > 0; }
};

/// The speed bound named `name` in a scenario (/time_step/speed_bound: "fastest_particle" or
/// "normal_approach"); anything else is a ConfigError listing both.
AdaptiveStep::SpeedBound speed_bound_named(std::string_view name);

/// Sets sys's step for the next interval_s by the rule (which must be on) and returns the number
/// of steps that fill it.
long long choose_step(System& sys, const AdaptiveStep& rule, double fixed_dt_s, double interval_s);

/// Puts the System's configured step back when it goes out of scope (System::end_adaptive_step):
/// whatever ends a phase run at the adaptive step, the next phase starts at the fixed one.
class AdaptiveStepScope {
 public:
  explicit AdaptiveStepScope(System& sys) : sys_(sys) {}
  ~AdaptiveStepScope() { sys_.end_adaptive_step(); }
  AdaptiveStepScope(const AdaptiveStepScope&) = delete;
  AdaptiveStepScope& operator=(const AdaptiveStepScope&) = delete;

 private:
  System& sys_;
};

/// Throws ConfigError naming `what` when the rule is on and dt_max_s < fixed_dt_s.
void check_adaptive_step(const AdaptiveStep& rule, double fixed_dt_s, const char* what);

}  // namespace gravsweep

#include "engine/scenario/time_step.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "engine/core/error.h"
#include "engine/core/registry.h"

namespace gravsweep {

namespace {
/// Relative slack of the whole-step count, so that an interval that is an exact multiple of the
/// target in decimal arithmetic is not given one more step by round-off.
constexpr double kWholeStepSlack = 1e-9;
}  // namespace

long long choose_step(System& sys, const AdaptiveStep& rule, double fixed_dt_s, double interval_s) {
  if (!rule.on()) throw std::logic_error("choose_step: the adaptive step is off");
  const double v_rel_m_s = rule.speed_bound == AdaptiveStep::SpeedBound::normal_approach
                               ? sys.max_approach_speed_m_s(interval_s)
                               : 2 * sys.max_particle_speed_m_s();
  const double target =
      std::clamp(sys.shortest_contact_time_s(v_rel_m_s) / rule.steps_per_contact, fixed_dt_s, rule.dt_max_s);
  const auto steps = std::max<long long>(1, static_cast<long long>(std::ceil(interval_s / target - kWholeStepSlack)));
  sys.set_dt_s(interval_s / static_cast<double>(steps));
  return steps;
}

namespace {
struct SpeedBoundRow {
  const char* name;
  AdaptiveStep::SpeedBound bound;
};
/// The speed bounds by name (/time_step/speed_bound).
constexpr SpeedBoundRow kSpeedBoundRows[] = {
    {"fastest_particle", AdaptiveStep::SpeedBound::fastest_particle},
    {"normal_approach", AdaptiveStep::SpeedBound::normal_approach},
};
}  // namespace

AdaptiveStep::SpeedBound speed_bound_named(std::string_view name) {
  return find_row(kSpeedBoundRows, name, "time step speed bound").bound;
}

void check_adaptive_step(const AdaptiveStep& rule, double fixed_dt_s, const char* what) {
  if (rule.on() && !(rule.dt_max_s >= fixed_dt_s))
    throw ConfigError(
        fmt::format("{}: time step cap dt_max_s = {} s must be >= dt_s = {} s", what, rule.dt_max_s, fixed_dt_s));
}

}  // namespace gravsweep

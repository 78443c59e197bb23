#include "scheduler/pipeline/scenario_defaults.h"

namespace gravsweep::pipeline {

using nlohmann::json;

int defaults_version(const json& scenario) {
  if (!scenario.is_object()) return kLegacyDefaultsVersion;
  const auto it = scenario.find("defaults_version");
  return it != scenario.end() && it->is_number_integer() ? it->get<int>() : kLegacyDefaultsVersion;
}

json with_current_defaults(json as_written) {
  if (as_written.is_object() && !as_written.contains("defaults_version"))
    as_written["defaults_version"] = kCurrentDefaultsVersion;
  return as_written;
}

namespace {

/// Whether the scenario (its schema defaults filled) is one version 2's adaptive step was checked on.
bool default_step_applies(const json& s) {
  if (defaults_version(s) < 2 || s.contains("time_step")) return false;
  const auto number = [&](const char* key) {
    const auto it = s.find(key);
    return it != s.end() && it->is_number() ? it->get<double>() : -1.0;
  };
  const double g = number("gravity_m_s2"), dt = number("dt_s");
  const auto law = s.find("contact");
  const bool hertz = law != s.end() && law->is_object() && law->value("law", json()) == "hertz";
  const bool euler = s.value("integrator", json()) == "semi_implicit_euler";
  return hertz && euler && dt > 0 && dt <= kDefaultDtMax_s && g >= kDefaultStepMinGravity_m_s2 &&
         g <= kDefaultStepMaxGravity_m_s2;
}

}  // namespace

void fill_versioned_defaults(json& s) {
  if (!s.is_object() || !default_step_applies(s)) return;
  s["time_step"] = {{"steps_per_contact", kDefaultStepsPerContact},
                    {"dt_max_s", kDefaultDtMax_s},
                    {"speed_bound", "normal_approach"}};
}

json id_point(const json& as_written, const json& validated) {
  const bool versioned_default = !as_written.contains("time_step") && validated.contains("time_step");
  if (versioned_default || !as_written.contains("defaults_version")) return as_written;
  json p = as_written;
  p.erase("defaults_version");
  return p;
}

}  // namespace gravsweep::pipeline

// The one trial record and its field table (see trial.h).
#include "results/measurements/trial.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace gravsweep::results {

const std::vector<TrialField>& trial_fields() {
  // key (JSON, CSV, SQLite), unit, required in trials.csv, member.
  static const std::vector<TrialField> fields = {
      {"trial_id", "", true, nullptr, &Trial::trial_id},
      {"trace_file", "", true, nullptr, &Trial::trace_file},
      {"gravity_m_s2", "m/s2", true, &Trial::gravity_m_s2, nullptr},
      {"impact_speed_m_s", "m/s", true, &Trial::impact_speed_m_s, nullptr},
      {"fill_height_m", "m", true, &Trial::fill_height_m, nullptr},  // dem: the measured surface (trace.h5)
      {"projectile_mass_kg", "kg", true, &Trial::projectile_mass_kg, nullptr},
      {"projectile_diameter_m", "m", true, &Trial::projectile_diameter_m, nullptr},
      {"grain_diameter_m", "m", true, &Trial::grain_diameter_m, nullptr},
      {"bulk_density_kg_m3", "kg/m3", true, &Trial::bulk_density_kg_m3, nullptr},
      {"sample_rate_hz", "Hz", true, &Trial::sample_rate_hz, nullptr},
      {"drop_height_m", "m", false, &Trial::drop_height_m, nullptr},
      {"filter_cutoff_hz", "Hz", false, &Trial::filter_cutoff_hz, nullptr},
      {"end_threshold_g", "1", false, &Trial::end_threshold_g, nullptr},
      {"end_speed_fraction", "1", false, &Trial::end_speed_fraction, nullptr},
      {"time_scale", "", false, nullptr, &Trial::time_scale},
      {"end_rule", "", false, nullptr, &Trial::end_rule},
      {"clipped_at_m_s2", "m/s2", false, &Trial::clipped_at_m_s2, nullptr},
      {"clipped_samples", "1", false, &Trial::clipped_samples, nullptr},
      {"clip_depth_error_m", "m", false, &Trial::clip_depth_error_m, nullptr},
      {"job_id", "", false, nullptr, &Trial::job_id},
      {"code_version", "", false, nullptr, &Trial::code_version},
  };
  return fields;
}

const std::vector<std::pair<std::string, std::string>>& trial_field_aliases() {
  static const std::vector<std::pair<std::string, std::string>> aliases = {
      {"impact_velocity_m_s", "impact_speed_m_s"},
  };
  return aliases;
}

std::string trial_field_key(const std::string& name) {
  for (const auto& [alias, key] : trial_field_aliases())
    if (name == alias) return key;
  return name;
}

namespace {

/// The physical range of a numeric field: min < value <= max (min <= value when min_inclusive).
struct PhysicalRange {
  const char* key;
  double min, max;
  bool min_inclusive;
  const char* what;
};

// Wide on purpose: a wrong unit (g in kg, mm in m) or a corrupt number (1e308, 1e-300) is refused,
// no real drop is (the weakest gravity of a small rubble pile to 100 g centrifuges, grains of dust
// to boulders). The lower bounds keep every accepted input's fit finite: a mass of 1e-300 kg made
// the fit's forces underflow and its held-out errors NaN.
constexpr PhysicalRange kPhysicalRanges[] = {
    {"gravity_m_s2", 1e-6, 1000, true, "a gravity"},
    {"impact_speed_m_s", 1e-6, 1000, true, "an impact speed"},
    {"fill_height_m", 1e-4, 100, true, "a bed depth"},
    {"projectile_mass_kg", 1e-6, 1000, true, "a projectile mass"},
    {"projectile_diameter_m", 1e-4, 10, true, "a projectile diameter"},
    {"grain_diameter_m", 1e-6, 1, true, "a grain diameter"},
    {"bulk_density_kg_m3", 0, 25000, true, "a bulk density (0: not measured)"},
    {"sample_rate_hz", 0, 1e9, false, "a sample rate"},
    {"drop_height_m", 0, 1000, true, "a drop height"},
    {"filter_cutoff_hz", 0, 1e9, false, "a filter cut-off"},
    {"end_threshold_g", 0, 100, false, "an end threshold in g"},
    {"end_speed_fraction", 0, 1, false, "a fraction of the impact speed"},
};

}  // namespace

std::string out_of_physical_range(const std::string& key, double value) {
  for (const auto& r : kPhysicalRanges) {
    if (key != r.key) continue;
    const bool above_min = r.min_inclusive ? value >= r.min : value > r.min;
    if (std::isfinite(value) && above_min && value <= r.max) return {};
    const auto f =
        std::find_if(trial_fields().begin(), trial_fields().end(), [&](const TrialField& fd) { return key == fd.key; });
    return fmt::format("{} {} value <= {:g} {}", r.what,
                       r.min_inclusive ? fmt::format("{:g} <=", r.min) : fmt::format("{:g} <", r.min), r.max,
                       f != trial_fields().end() ? f->unit : "");
  }
  return std::isfinite(value) ? std::string() : "a finite number";
}

void to_json(nlohmann::json& j, const Trial& t) {
  j = nlohmann::json::object();
  j["source"] = to_string(t.source);
  for (const auto& f : trial_fields()) {
    if (f.number)
      j[f.key] = t.*f.number;
    else
      j[f.key] = t.*f.text;
  }
  j["attributes"] = t.attributes;
}

void from_json(const nlohmann::json& j, Trial& t) {
  t = Trial{};
  if (j.contains("source")) t.source = trace_source_of(j.at("source").get<std::string>());
  for (const auto& f : trial_fields()) {
    const nlohmann::json* v = j.contains(f.key) ? &j.at(f.key) : nullptr;
    for (const auto& [alias, key] : trial_field_aliases())
      if ((!v || v->is_null()) && key == f.key && j.contains(alias)) v = &j.at(alias);
    if (!v || v->is_null()) continue;
    if (f.number)
      t.*f.number = v->get<double>();
    else
      t.*f.text = v->get<std::string>();
  }
  if (j.contains("attributes") && j.at("attributes").is_object())
    t.attributes = j.at("attributes").get<std::map<std::string, std::string>>();
}

double froude_time_factor(double gravity_m_s2, double projectile_diameter_m) {
  if (!(gravity_m_s2 > 0) || !(projectile_diameter_m > 0)) return 1.0;
  const double f =
      std::sqrt((gravity_m_s2 / projectile_diameter_m) / (kPaperGravity_m_s2 / kPaperProjectileDiameter_m));
  return std::abs(f - 1.0) < 1e-12 ? 1.0 : f;  // the paper's drop exactly as the paper processes it
}

TimeScale time_scale_for(const Trial& t) {
  if (!t.time_scale.empty()) return time_scale_of(t.time_scale);
  return t.source == TraceSource::dem ? TimeScale::froude : TimeScale::fixed;
}

MetricOptions metric_options(const Trial& t) {
  MetricOptions o;
  o.gravity_m_s2 = t.gravity_m_s2;
  o.cutoff_hz = t.filter_cutoff_hz;
  o.end_rule = end_rule_of(t.end_rule);
  if (time_scale_for(t) == TimeScale::froude) {
    const double f = froude_time_factor(t.gravity_m_s2, t.projectile_diameter_m);
    o.cutoff_hz *= f;
    o.end_hold_s /= f;
  }
  o.end_threshold_g = t.end_threshold_g;
  o.end_speed_fraction = t.end_speed_fraction;
  o.impact_speed_m_s = t.impact_speed_m_s;
  o.fill_height_m = t.fill_height_m;
  o.grain_diameter_m = t.grain_diameter_m;
  o.projectile_diameter_m = t.projectile_diameter_m;
  return o;
}

bool same_gravity_level(double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(std::abs(a), std::abs(b)); }

std::vector<double> gravity_levels_of(const std::vector<double>& gs) {
  std::vector<double> levels;
  for (double g : gs)
    if (std::none_of(levels.begin(), levels.end(), [&](double x) { return same_gravity_level(x, g); }))
      levels.push_back(g);
  std::sort(levels.rbegin(), levels.rend());
  return levels;
}

}  // namespace gravsweep::results

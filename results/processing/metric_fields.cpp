// The one table of the paper's metrics (see metric_fields.h).
#include "results/processing/metric_fields.h"

namespace gravsweep::results {

const std::vector<MetricField>& metric_fields() {
  // key, unit, headline, member (number / flag / text).
  static const std::vector<MetricField> fields = {
      {"vc_m_s", "m/s", true, &Metrics::vc_m_s, nullptr, nullptr},
      {"apeak_m_s2", "m/s2", true, &Metrics::apeak_m_s2, nullptr, nullptr},
      {"zstop_m", "m", true, &Metrics::zstop_m, nullptr, nullptr},
      {"tstop_s", "s", true, &Metrics::tstop_s, nullptr, nullptr},
      {"rebound", "1", true, nullptr, &Metrics::rebound, nullptr},
      {"start_depth_m", "m", false, &Metrics::start_depth_m, nullptr, nullptr},
      {"zstop_surface_m", "m", false, &Metrics::zstop_surface_m, nullptr, nullptr},
      {"cutoff_hz", "Hz", false, &Metrics::cutoff_hz, nullptr, nullptr},
      {"end_hold_s", "s", false, &Metrics::end_hold_s, nullptr, nullptr},
      {"t_start_s", "s", false, &Metrics::t_start_s, nullptr, nullptr},
      {"t_end_s", "s", false, &Metrics::t_end_s, nullptr, nullptr},
      {"depth_at_end_m", "m", false, &Metrics::depth_at_end_m, nullptr, nullptr},
      {"final_depth_m", "m", false, &Metrics::final_depth_m, nullptr, nullptr},
      {"note", "", false, nullptr, nullptr, &Metrics::note},
  };
  return fields;
}

nlohmann::json metric_json(const Metrics& m, const MetricField& f) {
  if (f.number) return m.*f.number;
  if (f.flag) return m.*f.flag;
  return m.*f.text;
}

void to_json(nlohmann::json& j, const Metrics& m) {
  j = nlohmann::json::object();
  for (const auto& f : metric_fields()) j[f.key] = metric_json(m, f);
}

std::vector<std::string> headline_metric_keys() {
  std::vector<std::string> keys;
  for (const auto& f : metric_fields())
    if (f.headline) keys.emplace_back(f.key);
  return keys;
}

}  // namespace gravsweep::results

// The base scenario of the tests that run real campaigns (submit, work) through the binary.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace gravsweep::test {

/// The tiny scenario of the integration tests: an 8 cm cup of 1 cm grains, 4 cm deep (a bed
/// takes about a second, a drop less).
inline std::string tiny_base() {
  return R"({
    "name": "tiny", "gravity_m_s2": 9.81,
    "container": {"diameter_m": 0.08, "fill_height_m": 0.04},
    "dt_s": 1e-5,
    "bed": {"seed": 7, "dt_s": 1e-5, "settle": {"max_time_s": 0.3, "rms_speed_m_s": 1e-4,
            "max_speed_m_s": 5e-3}, "relax_time_s": 0.02},
    "projectile": {"diameter_m": 0.03, "mass_kg": 0.03, "impact_speed_m_s": 0.5,
                   "lateral_offset_max_grain_diameters": 0.5, "seed": 3},
    "stop": {"max_time_s": 0.25}
  })";
}

/// A sweep spec (JSON text) named `sweep`: one bed of the tiny scenario and one drop on it per
/// impact speed (m/s).
inline std::string tiny_speed_sweep(const std::string& sweep, const std::vector<double>& speeds_m_s) {
  const nlohmann::json doc = {
      {"sweep", sweep},
      {"base", nlohmann::json::parse(tiny_base())},
      {"axes", {{{"name", "impact_speed_m_s"}, {"pointer", "/projectile/impact_speed_m_s"}, {"values", speeds_m_s}}}}};
  return doc.dump();
}

}  // namespace gravsweep::test

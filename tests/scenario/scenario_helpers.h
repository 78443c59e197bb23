// Small scenarios for the tests: a few hundred grains in a narrow container, large dt, so the
// whole pipeline (fill, settle, flatten, drop, metrics) runs in seconds.
#pragma once
#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include "tests/common/temp_dir.h"  // TempDir

namespace gravsweep::test {

/// A checkpoint interval that never passes during a test: a job checkpoints only when asked to stop.
constexpr double kNeverDue_s = 1e6;

/// 9 cm container, 5 cm fill (about 330 grains of 1 cm kept of 420 poured), a 4 cm, 250 g
/// projectile at 1 m/s; dt = 10 us (below the Hertz bound of ~14 us for these grains).
inline nlohmann::json tiny_scenario() {
  return nlohmann::json::parse(R"({
    "name": "tiny",
    "container": {"diameter_m": 0.09, "fill_height_m": 0.05},
    "dt_s": 1e-5,
    "bed": {"seed": 7, "dt_s": 1e-5, "settle": {"max_time_s": 0.3, "rms_speed_m_s": 1e-4,
            "max_speed_m_s": 5e-3}, "relax_time_s": 0.02},
    "projectile": {"diameter_m": 0.04, "mass_kg": 0.25, "impact_speed_m_s": 1.0,
                   "lateral_offset_max_grain_diameters": 0.5, "seed": 3},
    "stop": {"max_time_s": 0.3}
  })");
}

}  // namespace gravsweep::test

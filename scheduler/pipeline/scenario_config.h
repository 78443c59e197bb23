// What the scenario's validation (scenario_spec.cpp) and its translation into engine inputs
// (scenario_params.cpp) share; not part of the pipeline's interface.
#pragma once
#include <nlohmann/json.hpp>

#include "engine/system/system.h"

namespace gravsweep::pipeline::detail {

/// The system configuration common to preparation and drop (dt and gravity set by the caller),
/// with the body materials `m` (/materials for the drop, bed_materials() for the preparation).
SystemConfig base_config(const nlohmann::json& s, const nlohmann::json& m);

}  // namespace gravsweep::pipeline::detail

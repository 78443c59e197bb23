// What the scenario's validation (scenario_spec.cpp) and the engine's inputs made from the typed
// scenario (scenario_engine.cpp) share; not part of the pipeline's interface.
#pragma once
#include <string>

#include "engine/system/system.h"
#include "scheduler/pipeline/scenario.h"

namespace gravsweep::pipeline::detail {

/// The system configuration common to preparation and drop (dt and gravity set by the caller),
/// with the body materials `m` (/materials for the drop, Scenario::bed_materials() for the
/// preparation).
SystemConfig base_config(const ContactSettings& contact, const MaterialSet& m, const std::string& integrator,
                         int threads);

}  // namespace gravsweep::pipeline::detail

// The spec schemas of schemas/ (scenario, sweep, model), compiled into the binary, and their
// validators: the one way a spec file is checked (spec/json_schema.h). Hand checks stay only for
// what a schema cannot say (cross-field rules), next to the spec they belong to:
// scheduler/pipeline/scenario_spec.cpp, scheduler/sweep/spec.cpp, results/model/model.cpp.
#pragma once
#include <string>

#include "spec/json_schema.h"

namespace gravsweep::spec {

enum class Schema {
  scenario,  ///< schemas/scenario.schema.json: one impact (gravsweep run, a sweep's base)
  sweep,     ///< schemas/sweep.schema.json: a sweep spec (gravsweep submit)
  model,     ///< schemas/model.schema.json: a collision model file (gravsweep model fit --model FILE)
};

/// The schema's text as compiled in (tests compare it with the file in schemas/).
const std::string& schema_text(Schema which);

/// The validator of that schema (built once).
const SchemaValidator& validator(Schema which);

}  // namespace gravsweep::spec

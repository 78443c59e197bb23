// The spec schemas of schemas/ (scenario, sweep, model), compiled into the binary, and their
// validators: the one way a spec file is read (read_spec_file) and checked (spec/json_schema.h),
// problems collected in spec/problems.h. Hand checks stay only for what a schema cannot say
// (cross-field rules), next to the spec they belong to: scheduler/pipeline/scenario_spec.cpp,
// scheduler/sweep/spec.cpp, results/model/model_spec.cpp.
#pragma once
#include <nlohmann/json.hpp>

#include <filesystem>
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

/// What a file of that schema is called in messages: "scenario file", "sweep spec file", "model spec file".
const char* file_kind(Schema which);

/// A spec file, read and parsed (validate it with validator(which).collect). Throws SpecError
/// when it cannot be read (source: the file; found: why, e.g. "a folder, not a file"; expected: "a
/// readable <file_kind>") or is not JSON (source: "FILE:LINE:COLUMN", as compilers name a place;
/// found: what is wrong; expected: "valid JSON"); a sweep spec's as SpecError::sweep_spec.
nlohmann::json read_spec_file(const std::filesystem::path& path, Schema which);

/// Spec text not read from a file (a test's, a benchmark's), parsed as read_spec_file parses a
/// file's; `source` names it in errors ("SOURCE:LINE:COLUMN").
nlohmann::json parse_spec_text(const std::string& text, const std::string& source, Schema which);

}  // namespace gravsweep::spec

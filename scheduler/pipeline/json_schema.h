// A small validator for the subset of JSON Schema (draft 2020-12) that gravsweep's spec schemas use:
// type (object, number, integer, string, boolean), properties, additionalProperties: false,
// required, enum, minimum, maximum, exclusiveMinimum, exclusiveMaximum, default, and $ref to
// "#/$defs/<name>" (with sibling keywords). Defaults are inserted into the instance, so after
// validation the instance is complete. Debian 12 packages no C++ JSON-schema validator, hence this.
// Validation does not stop at the first violation: every one is collected (JSON pointer of the
// field, what was found, what was expected) and SpecError lists them all.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "scheduler/pipeline/json_pointer.h"  // pointer_token

namespace gravsweep::pipeline {

/// One problem of a spec: where, what was found, what was expected.
struct SpecProblem {
  std::string pointer;   ///< JSON pointer of the field ("" = the document)
  std::string found;     ///< the value found, as compact JSON (or "nothing (missing)")
  std::string expected;  ///< what was expected
};

/// Spec fields are invalid: every problem found, in order, in a scenario spec (this validator,
/// scenario_spec.h) or a sweep spec (scheduler/sweep/spec.h): the one error type of both. Derives
/// from ConfigError, so the CLI exits with code 2. pointer()/found()/expected() are those of the
/// first problem.
class SpecError : public ConfigError {
 public:
  /// A scenario's problems: "SOURCE: POINTER = FOUND is invalid: expected X" (several: counted,
  /// then one a line).
  SpecError(std::string source, std::string pointer, std::string found, std::string expected);
  SpecError(std::string source, std::vector<SpecProblem> problems);  ///< at least one problem
  /// A sweep spec's problems: "FILE: invalid sweep spec (N problems); nothing was written", then
  /// "  POINTER: found F, expected E" for each (at least one problem).
  [[nodiscard]] static SpecError sweep_spec(std::string file, std::vector<SpecProblem> problems);
  [[nodiscard]] const std::string& source() const { return source_; }
  [[nodiscard]] const std::vector<SpecProblem>& problems() const { return problems_; }
  [[nodiscard]] const std::string& pointer() const { return problems_.front().pointer; }
  [[nodiscard]] const std::string& found() const { return problems_.front().found; }
  [[nodiscard]] const std::string& expected() const { return problems_.front().expected; }

 private:
  struct Message {
    std::string text;
  };
  SpecError(Message message, std::string source, std::vector<SpecProblem> problems);
  std::string source_;
  std::vector<SpecProblem> problems_;
};

class SchemaValidator {
 public:
  explicit SchemaValidator(nlohmann::json schema);
  /// Validates `instance` in place (inserting defaults); throws SpecError listing every problem,
  /// `source` naming the file.
  void validate(nlohmann::json& instance, const std::string& source) const;
  /// Validates in place and appends every problem found (nothing thrown for bad input).
  void collect(nlohmann::json& instance, std::vector<SpecProblem>& problems) const;
  [[nodiscard]] const nlohmann::json& schema() const { return schema_; }

 private:
  nlohmann::json schema_;
  [[nodiscard]] nlohmann::json resolve(const nlohmann::json& s) const;
  void check(nlohmann::json& node, const nlohmann::json& schema, const std::string& pointer,
             std::vector<SpecProblem>& problems) const;
};

}  // namespace gravsweep::pipeline

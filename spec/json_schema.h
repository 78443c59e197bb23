// The one validator of gravsweep's spec files (scenario, sweep and model schemas in schemas/; see
// spec/schemas.h): the subset of JSON Schema (draft 2020-12) those schemas use: type (object,
// array, number, integer, string, boolean), properties, additionalProperties: false, required,
// enum, minimum, maximum, exclusiveMinimum, exclusiveMaximum, minLength, maxLength, pattern
// (ECMAScript), items, minItems, uniqueItems (numbers by value: 1 and 1.0 are the same), oneOf,
// not, default, and $ref to "#/$defs/<name>" (with sibling keywords). Defaults are inserted into
// the instance, so after validation the instance is complete. Debian 12 packages no C++
// JSON-schema validator, hence this. Validation does not stop at the first violation: every one is
// collected (JSON pointer of the field, what was found, what was expected) and SpecError lists them
// all. A schema keyword outside the subset is refused when the validator is built (std::logic_error),
// never silently ignored.
#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "spec/json_pointer.h"  // pointer_child

namespace gravsweep::spec {

/// One problem of a spec: where, what was found, what was expected.
struct SpecProblem {
  std::string pointer;   ///< JSON pointer of the field ("" = the document)
  std::string found;     ///< the value found, as compact JSON with its type ("1.62" (string)), or "nothing (missing)"
  std::string expected;  ///< what was expected
};

/// Spec fields are invalid: every problem found, in order, in a scenario spec
/// (scheduler/pipeline/scenario_spec.h), a sweep spec (scheduler/sweep/spec.h) or a model spec
/// (results/model/model_spec.h): the one error type of all three. Derives
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

/// The JSON type of `v` as messages name it: null, boolean, integer, number, string, array, object.
std::string type_name(const nlohmann::json& v);

/// An integer, or a float with an integral value that a double holds exactly (|v| < 2^53): a value
/// a spec may give where a count or an integer axis is meant (`3` and `3.0` alike).
bool is_exact_integer(const nlohmann::json& v);

/// `v` as a problem shows it: compact JSON (cut at 80 characters) and its JSON type, `"1.62" (string)`.
std::string shown_value(const nlohmann::json& v);

class SchemaValidator {
 public:
  /// Throws std::logic_error when the schema uses a keyword outside the subset above.
  explicit SchemaValidator(nlohmann::json schema);
  /// Validates `instance` in place (inserting defaults); throws SpecError listing every problem,
  /// `source` naming the file.
  void validate(nlohmann::json& instance, const std::string& source) const;
  /// Validates in place and appends every problem found (nothing thrown for bad input).
  void collect(nlohmann::json& instance, std::vector<SpecProblem>& problems) const;
  /// Validates `node` against the schema's definition "#/$defs/<definition>" (a value a spec
  /// derives rather than writes, e.g. a column name from a pointer), problems at `pointer`.
  void collect_definition(nlohmann::json& node, const std::string& definition, const std::string& pointer,
                          std::vector<SpecProblem>& problems) const;
  [[nodiscard]] const nlohmann::json& schema() const { return schema_; }

 private:
  nlohmann::json schema_;
  [[nodiscard]] nlohmann::json resolve(const nlohmann::json& s) const;
  /// `s` itself when it has no $ref, else its merge with the definition, kept in `storage`.
  const nlohmann::json& resolved(const nlohmann::json& s, nlohmann::json& storage) const;
  void check(nlohmann::json& node, const nlohmann::json& schema, const std::string& pointer,
             std::vector<SpecProblem>& problems) const;
  /// type, enum, not: false when the node is not of the type (nothing below it is checked).
  bool check_type(nlohmann::json& node, const nlohmann::json& s, const std::string& pointer,
                  std::vector<SpecProblem>& problems) const;
  void check_number(const nlohmann::json& node, const nlohmann::json& s, const std::string& pointer,
                    std::vector<SpecProblem>& problems) const;
  void check_string(const nlohmann::json& node, const nlohmann::json& s, const std::string& pointer,
                    std::vector<SpecProblem>& problems) const;
  void check_array(nlohmann::json& node, const nlohmann::json& s, const std::string& pointer,
                   std::vector<SpecProblem>& problems) const;
  void check_object(nlohmann::json& node, const nlohmann::json& s, const std::string& pointer,
                    std::vector<SpecProblem>& problems) const;
  void check_one_of(nlohmann::json& node, const nlohmann::json& s, const std::string& pointer,
                    std::vector<SpecProblem>& problems) const;
};

}  // namespace gravsweep::spec

// A small validator for the subset of JSON Schema (draft 2020-12) that gravsweep's spec schemas use:
// type (object, number, integer, string, boolean), properties, additionalProperties: false,
// required, enum, minimum, maximum, exclusiveMinimum, exclusiveMaximum, default, and $ref to
// "#/$defs/<name>" (with sibling keywords). Defaults are inserted into the instance, so after
// validation the instance is complete. Debian 12 packages no C++ JSON-schema validator, hence this.
// The first violation throws SpecError with the JSON pointer of the field, what was found and what
// was expected.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "engine/core/error.h"

namespace gravsweep::pipeline {

/// A spec field is invalid. Derives from ConfigError, so the CLI exits with code 2.
class SpecError : public ConfigError {
 public:
  SpecError(std::string source, std::string pointer, std::string found, std::string expected);
  [[nodiscard]] const std::string& source() const { return source_; }
  [[nodiscard]] const std::string& pointer() const { return pointer_; }
  [[nodiscard]] const std::string& found() const { return found_; }
  [[nodiscard]] const std::string& expected() const { return expected_; }

 private:
  std::string source_, pointer_, found_, expected_;
};

/// JSON pointer escaping of one reference token (RFC 6901: ~ -> ~0, / -> ~1).
std::string pointer_token(const std::string& key);

class SchemaValidator {
 public:
  explicit SchemaValidator(nlohmann::json schema);
  /// Validates `instance` in place (inserting defaults); `source` names the file in messages.
  void validate(nlohmann::json& instance, const std::string& source) const;
  [[nodiscard]] const nlohmann::json& schema() const { return schema_; }

 private:
  nlohmann::json schema_;
  [[nodiscard]] nlohmann::json resolve(const nlohmann::json& s) const;
  void check(nlohmann::json& node, const nlohmann::json& schema, const std::string& pointer,
             const std::string& source) const;
};

}  // namespace gravsweep::pipeline

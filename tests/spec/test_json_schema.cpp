// The validator of spec/json_schema.h, keyword by keyword: each problem with the JSON pointer, the
// value found (with its type) and what was expected; keywords outside the subset refused.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <stdexcept>

#include "spec/json_schema.h"

using gravsweep::spec::SchemaValidator;
using gravsweep::spec::SpecProblem;
using nlohmann::json;

namespace {

std::vector<SpecProblem> problems(const json& schema, json instance) {
  std::vector<SpecProblem> out;
  SchemaValidator(schema).collect(instance, out);
  return out;
}

}  // namespace

TEST(JsonSchema, AKeywordOutsideTheSubsetIsRefusedNotIgnored) {
  // "anyOf" would be silently skipped by a validator that only knows oneOf: a spec it should
  // refuse would pass.
  const json schema = json::parse(R"({"type": "object", "properties": {"x": {"anyOf": [{"type": "string"}]}}})");
  try {
    SchemaValidator v(schema);
    FAIL() << "anyOf accepted";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("'anyOf' at '/properties/x'"), std::string::npos) << e.what();
  }
}

TEST(JsonSchema, ArraysItemsLengthAndUniqueValuesByNumber) {
  const json schema = json::parse(R"({"type": "array", "minItems": 1, "uniqueItems": true,
                                      "items": {"type": "number", "minimum": 0}})");
  auto ps = problems(schema, json::array());
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].pointer, "");
  EXPECT_EQ(ps[0].expected, "a non-empty array");
  // 1 and 1.0 are the same number: the second is the repeat, named by its index.
  ps = problems(schema, json::parse("[1, -2, 1.0]"));
  ASSERT_EQ(ps.size(), 2u);
  EXPECT_EQ(ps[0].pointer, "/1");
  EXPECT_EQ(ps[0].found, "-2 (integer)");
  EXPECT_EQ(ps[0].expected, "a number >= 0");
  EXPECT_EQ(ps[1].pointer, "/2");
  EXPECT_NE(ps[1].expected.find("repeats an earlier value"), std::string::npos);
}

TEST(JsonSchema, StringsPatternLengthAndNotEnum) {
  const json schema = json::parse(R"({"type": "string", "pattern": "^[a-z_][a-z0-9_]*$", "maxLength": 8,
                                      "not": {"enum": ["job_id"]}, "description": "a column name"})");
  EXPECT_TRUE(problems(schema, "depth_m").empty());
  auto ps = problems(schema, "Depth");
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].found, "\"Depth\" (string)");
  EXPECT_EQ(ps[0].expected, "a string matching ^[a-z_][a-z0-9_]*$ (a column name)");
  ps = problems(schema, "much_too_long");
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].expected, "a string of at most 8 characters (a column name)");
  ps = problems(schema, "job_id");
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].expected, "none of [\"job_id\"] (a column name)");
}

TEST(JsonSchema, IntegersBetweenBoundsAndIntegralFloats) {
  const json schema = json::parse(R"({"type": "integer", "minimum": 1, "maximum": 100})");
  auto ps = problems(schema, 0);
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].expected, "an integer between 1 and 100");
  ps = problems(schema, 2.5);
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].expected, "an integer");
  json three = 3.0;  // an integral float is an integer, and becomes one
  std::vector<SpecProblem> none;
  SchemaValidator(schema).collect(three, none);
  EXPECT_TRUE(none.empty());
  EXPECT_TRUE(three.is_number_integer());
}

TEST(JsonSchema, OneOfFieldsSaysWhichAreMissingOrTooMany) {
  const json schema = json::parse(R"({"type": "object", "oneOf": [{"required": ["values"]}, {"required": ["range"]}],
                                      "properties": {"values": {"type": "array"}, "range": {"type": "object"}}})");
  EXPECT_TRUE(problems(schema, json::parse(R"({"values": [1]})")).empty());
  auto ps = problems(schema, json::object());
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].found, "none of \"values\"/\"range\"");
  EXPECT_EQ(ps[0].expected, "exactly one of \"values\" or \"range\"");
  ps = problems(schema, json::parse(R"({"values": [1], "range": {}})"));
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].found, "more than one of \"values\"/\"range\"");
}

TEST(JsonSchema, OneOfObjectsReportsTheBranchTheValueWasMeantFor) {
  // An axis or a zip group: a bad axis is reported as an axis (its own field), not as "not a zip".
  const json schema = json::parse(R"({"$defs": {
      "axis": {"type": "object", "additionalProperties": false, "required": ["pointer"],
               "properties": {"pointer": {"type": "string"}, "values": {"type": "array"}}},
      "zip": {"type": "object", "additionalProperties": false, "required": ["zip"],
              "properties": {"zip": {"type": "array"}}}},
    "type": "array", "items": {"oneOf": [{"$ref": "#/$defs/axis"}, {"$ref": "#/$defs/zip"}]}})");
  auto ps = problems(schema, json::parse(R"([{"pointer": "/g", "values": 3}])"));
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].pointer, "/0/values");
  EXPECT_EQ(ps[0].expected, "an array");
  ps = problems(schema, json::parse(R"([{"zip": [], "colour": 1}])"));
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].pointer, "/0/colour");
  EXPECT_EQ(ps[0].found, "unknown key \"colour\"");
  ps = problems(schema, json::parse(R"([7])"));
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].found, "7 (integer)");
  EXPECT_EQ(ps[0].expected.rfind("either an object", 0), 0u) << ps[0].expected;
}

TEST(JsonSchema, DefaultsAreInsertedAndDefinitionsValidateDerivedValues) {
  const json schema = json::parse(R"({"type": "object", "properties": {"n": {"type": "integer", "default": 3}},
                                      "$defs": {"column": {"type": "string", "pattern": "^[a-z]+$"}}})");
  json doc = json::object();
  std::vector<SpecProblem> ps;
  SchemaValidator v(schema);
  v.collect(doc, ps);
  EXPECT_TRUE(ps.empty());
  EXPECT_EQ(doc["n"], 3);
  json derived = "Bad_Name";
  v.collect_definition(derived, "column", "/axes/0/pointer", ps);
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].pointer, "/axes/0/pointer");
}

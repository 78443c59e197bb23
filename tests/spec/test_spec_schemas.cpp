// The three spec schemas of schemas/, as compiled in (spec/schemas.h), check what they are meant to:
// every shipped sweep spec passes, sweep and model files with problems are refused at the same
// pointers the hand checks used, with the file named: the specs are checked by their schemas.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/common/temp_dir.h"
#include "results/model/model_spec.h"
#include "scheduler/sweep/spec.h"
#include "spec/json_text.h"
#include "spec/schemas.h"

using namespace gravsweep;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

json read_json(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return json::parse(ss.str());
}

bool has(const std::vector<spec::SpecProblem>& ps, const std::string& pointer, const std::string& expected_part) {
  for (const auto& p : ps)
    if (p.pointer == pointer && p.expected.find(expected_part) != std::string::npos) return true;
  return false;
}

std::vector<spec::SpecProblem> sweep_problems(const json& doc) {
  try {
    sweep::load_spec_text(doc.dump(), "spec.json", ".");
  } catch (const spec::SpecError& e) {
    return e.problems();
  }
  return {};
}

}  // namespace

TEST(SpecSchemas, TheCompiledSchemasAreTheRepositorysFiles) {
  const fs::path dir = fs::path(GRAVSWEEP_SOURCE_DIR) / "schemas";
  EXPECT_EQ(read_json(dir / "sweep.schema.json"), json::parse(spec::schema_text(spec::Schema::sweep)));
  EXPECT_EQ(read_json(dir / "model.schema.json"), json::parse(spec::schema_text(spec::Schema::model)));
  EXPECT_EQ(read_json(dir / "scenario.schema.json"), json::parse(spec::schema_text(spec::Schema::scenario)));
}

TEST(SpecSchemas, EveryShippedSweepSpecPassesItsSchema) {
  int checked = 0;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(GRAVSWEEP_SOURCE_DIR) / "examples")) {
    if (e.path().extension() != ".json") continue;
    json doc = read_json(e.path());
    if (!doc.contains("sweep")) continue;
    std::vector<spec::SpecProblem> ps;
    spec::validator(spec::Schema::sweep).collect(doc, ps);
    EXPECT_TRUE(ps.empty()) << e.path() << ": " << ps.front().pointer << " " << ps.front().expected;
    ++checked;
  }
  EXPECT_GE(checked, 7);
}

TEST(SpecSchemas, SweepSpecProblemsComeFromTheSchemaAtTheirPointers) {
  // Each of these was a hand check in scheduler/sweep/spec.cpp; the schema reports it now, at the
  // same pointer, and the checks across fields still run on the sound axes.
  const json doc = json::parse(R"({
    "sweep": "s", "base": {"g": 9.81, "seed": 1},
    "axes": [{"pointer": "/g", "range": {"start": 1, "stop": 2, "step": 0}},
             {"pointer": "/g", "name": "kind", "values": [1]},
             {"pointer": "/missing", "values": [1, 1.0]},
             {"zip": [{"pointer": "/g", "values": [1, 2]}]}],
    "repeats": {"pointer": "/seed", "count": 0},
    "max_attempts": 101, "priority": 1.5})");
  const auto ps = sweep_problems(doc);
  EXPECT_TRUE(has(ps, "/axes/0/range/step", "a positive number"));
  EXPECT_TRUE(has(ps, "/axes/1/name", "none of"));                       // a fixed results column
  EXPECT_TRUE(has(ps, "/axes/2/values/1", "repeats an earlier value"));  // 1 and 1.0
  EXPECT_TRUE(has(ps, "/axes/3/zip", "at least two axes"));
  EXPECT_TRUE(has(ps, "/repeats/count", "between 1 and 1000000"));
  EXPECT_TRUE(has(ps, "/max_attempts", "an integer between 1 and 100"));
  EXPECT_TRUE(has(ps, "/priority", "an integer"));
  // An axis the schema found bad is not checked again across fields (no second problem at
  // /axes/2/pointer for the missing base field).
  EXPECT_FALSE(has(ps, "/axes/2/pointer", "present in the base")) << ps.size();
  EXPECT_EQ(ps.size(), 7u);
}

TEST(SpecSchemas, ADerivedColumnNameObeysTheSchemasRule) {
  const json doc = json::parse(R"({"sweep": "s", "base": {"Job": {"Id": 1}, "runtime": {"s": 2}},
                                   "axes": [{"pointer": "/runtime/s", "values": [1, 2]}]})");
  const auto ps = sweep_problems(doc);
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].pointer, "/axes/0/pointer");
  EXPECT_NE(ps[0].expected.find("\"runtime_s\" is not one"), std::string::npos) << ps[0].expected;
}

TEST(SpecSchemas, AModelFileIsCheckedByItsSchemaEveryProblemWithItsPointer) {
  test::TempDir d;
  const fs::path bad = d.path / "model.json";
  std::ofstream(bad) << R"({"terms": [{"name": "base"}, {"name": "depth_frction"}, {"name": "z^1*v^1", "scale": -1},
                            {"name": "viscous_drag", "shared": "yes", "colour": 1}]})";
  try {
    results::parse_model(bad.string());
    FAIL() << "a bad model file accepted";
  } catch (const spec::SpecError& e) {
    const auto& ps = e.problems();
    EXPECT_EQ(e.source(), bad.string());
    EXPECT_TRUE(has(ps, "/terms/1/name", "a registered term")) << e.what();
    EXPECT_TRUE(has(ps, "/terms/2/scale", "a number > 0")) << e.what();
    EXPECT_TRUE(has(ps, "/terms/3/shared", "a boolean")) << e.what();
    EXPECT_TRUE(has(ps, "/terms/3/colour", "one of: g_power, name, scale, shared")) << e.what();
    EXPECT_EQ(ps.size(), 4u) << e.what();
  }
  // A generated form passes the schema; its numbers are then checked by the term lookup.
  const fs::path good = d.path / "good.json";
  std::ofstream(good) << R"({"terms": [{"name": "base"}, {"name": "z^1*v^0.5", "shared": true}]})";
  const auto m = results::parse_model(good.string());
  ASSERT_EQ(m.terms.size(), 2u);
  EXPECT_FALSE(m.terms[1].per_gravity);
  const fs::path huge = d.path / "huge.json";
  std::ofstream(huge) << R"j({"terms": [{"name": "exp(-z/0)"}]})j";
  try {
    results::parse_model(huge.string());
    FAIL() << "a length of 0 accepted";
  } catch (const spec::SpecError& e) {
    EXPECT_EQ(e.pointer(), "/terms/0/name") << e.what();
  }
}

// A key given twice in one object is refused at its second occurrence, with its JSON pointer and
// line: a parser keeps one of the two silently (nlohmann's the last), so a sweep with "sweep" twice
// ran under the second name.
TEST(SpecSchemas, AKeyGivenTwiceInOneObjectIsRefusedWithItsPointer) {
  nlohmann::json doc;
  const auto err = spec::parse_json_text(
      "{\"a\": 1, \"b\": {\"c\": [{\"x\": 1}, {\"y\": 1,\n \"x\": 2, \"y\": 3}]}, \"x\": 4}", doc);
  ASSERT_TRUE(err.has_value());
  EXPECT_EQ(err->pointer, "/b/c/1/y");
  EXPECT_EQ(err->line, 2u);
  EXPECT_EQ(err->column, 10u);
  EXPECT_NE(err->what.find("\"y\" given twice"), std::string::npos) << err->what;
  EXPECT_FALSE(spec::parse_json_text("{\"a\": {\"x\": 1}, \"b\": {\"x\": 2}, \"c\": [{\"x\": 1}, {\"x\": 2}]}", doc))
      << "the same key in different objects is fine";
  test::TempDir d;
  const fs::path f = d.path / "sweep.json";
  std::ofstream(f) << "{\"sweep\": \"first\",\n \"base\": {},\n \"sweep\": \"second\"}\n";
  try {
    spec::read_spec_file(f, spec::Schema::sweep);
    FAIL() << "a duplicate key accepted";
  } catch (const spec::SpecError& e) {
    EXPECT_EQ(e.pointer(), "/sweep") << e.what();
    EXPECT_NE(std::string(e.what()).find(f.string() + ":3:2"), std::string::npos) << e.what();
  }
}

TEST(SpecSchemas, AModelFileWithBadJsonNamesItsLineAndColumn) {
  // Model files are read like scenario and sweep specs (spec::read_spec_file): FILE:LINE:COLUMN.
  test::TempDir d;
  const fs::path f = d.path / "model.json";
  std::ofstream(f) << "{\"terms\": [\n  {\"name\": \"base\"},\n  {\"name\": }\n]}\n";
  try {
    results::parse_model(f.string());
    FAIL() << "bad JSON accepted";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(f.string() + ":3:", 0), 0u) << m;
    EXPECT_NE(m.find("expected valid JSON"), std::string::npos) << m;
  }
}

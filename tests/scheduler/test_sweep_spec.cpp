// Sweep specs: expansion (lists, ranges, zips, repeats), and refusal of malformed specs with the
// JSON pointer, the value found and the type expected.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <set>

#include "scheduler/queue/canonical.h"
#include "scheduler/sweep/impact_kinds.h"
#include "scheduler/sweep/spec.h"
#include "scheduler/sweep/sweep_kind.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep::sweep;
using nlohmann::json;

namespace {

const json kBase = json::parse(R"({"g": 9.81, "speed_m_s": 1.0, "fill_m": 0.1, "dt_s": 1e-5, "seed": 1,
                                    "name": "x", "nested": {"k": 2.5}})");

SweepSpec parse(const json& doc) { return load_spec_text(doc.dump(), "spec.json", "."); }

/// Bed key of the test: beds differ by gravity, fill and seed (not by speed).
CheckedPoint test_bed_key(const json& s) {
  return {s.dump(), {{"g", s["g"]}, {"fill_m", s["fill_m"]}, {"seed", s["seed"]}}, {}};
}

/// The impact kind's shape (a drop per point, a bed per key) on the test's bed key.
const SweepKind& test_impact() {
  static const SweepKind k{"impact", "test", {}, shared_input_planner(test_bed_key, drop_kind(), bed_kind()), {}};
  return k;
}

std::vector<SpecProblem> problems_of(const json& doc) {
  try {
    parse(doc);
  } catch (const SpecError& e) {
    return e.problems();
  }
  return {};
}

bool has_problem(const std::vector<SpecProblem>& ps, const std::string& ptr, const std::string& found_part,
                 const std::string& expected_part) {
  for (const auto& p : ps)
    if (p.pointer == ptr && p.found.find(found_part) != std::string::npos &&
        p.expected.find(expected_part) != std::string::npos)
      return true;
  return false;
}

}  // namespace

TEST(SweepSpec, ProductOfListsRangesZipsAndRepeats) {
  const json doc = {
      {"sweep", "s"},
      {"base", kBase},
      {"axes",
       {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {9.81, 1.62}}},
        {{"name", "speed_m_s"}, {"pointer", "/speed_m_s"}, {"range", {{"start", 0.1}, {"stop", 0.3}, {"step", 0.1}}}},
        {{"zip",
          {{{"name", "fill_m"}, {"pointer", "/fill_m"}, {"values", {0.1, 0.21}}},
           {{"name", "dt_s"}, {"pointer", "/dt_s"}, {"values", {1e-5, 2e-5}}}}}}}},
      {"repeats", {{"pointer", "/seed"}, {"count", 3}, {"start", 1}}}};
  const SweepSpec spec = parse(doc);
  EXPECT_EQ(spec.points(), 2u * 3u * 2u * 3u);
  // The range is 0.1, 0.2, 0.3 exactly as literals, not 0.30000000000000004.
  ASSERT_EQ(spec.groups[1].axes[0].values.size(), 3u);
  EXPECT_EQ(gravsweep::queue::canonical_json(spec.groups[1].axes[0].values[2]), "0.3");
  // The parsed spec is the sweep the queue stores: a results column per axis, in axis order, with
  // every value the axis takes (the zip's two axes are two columns; the repeats' column last).
  std::vector<std::string> names;
  for (const auto& [name, values] : spec.columns) names.push_back(name);
  EXPECT_EQ(names, (std::vector<std::string>{"gravity_m_s2", "speed_m_s", "fill_m", "dt_s", "seed"}));
  EXPECT_EQ(spec.columns[1].second, spec.groups[1].axes[0].values);
  EXPECT_EQ(spec.name, "s");
  EXPECT_EQ(json::parse(spec.spec_json)["base"], spec.base);
  const auto jobs = expand(spec, test_impact());
  std::size_t beds = 0, drops = 0;
  std::set<std::string> ids;
  for (const auto& j : jobs) {
    ids.insert(j.job_id);
    if (j.kind == "bed") {
      ++beds;
      EXPECT_EQ(j.priority, 1);
      EXPECT_FALSE(j.params.contains("speed_m_s"));  // varies within the bed
    } else {
      ++drops;
      ASSERT_EQ(j.deps.size(), 1u);
      EXPECT_EQ(j.params.size(), 5u);
      EXPECT_EQ(json::parse(j.scenario_json)["nested"]["k"], 2.5);  // untouched fields kept
    }
  }
  EXPECT_EQ(drops, 36u);
  EXPECT_EQ(beds, 2u * 2u * 3u);  // gravity x (fill, dt zipped) x seed
  EXPECT_EQ(ids.size(), jobs.size()) << "job ids must be distinct";
  // zip: fill 0.21 always comes with dt 2e-5
  for (const auto& j : jobs)
    if (j.kind == "drop") {
      const json s = json::parse(j.scenario_json);
      EXPECT_EQ(s["fill_m"] == 0.21, s["dt_s"] == 2e-5);
    }
}

TEST(SweepSpec, ExpansionIsDeterministicAndExtensionKeepsIds) {
  json doc = {{"sweep", "s"}, {"base", kBase}, {"axes", {{{"pointer", "/g"}, {"values", {9.81, 1.62}}}}}};
  const auto a = expand(parse(doc), test_impact());
  const auto b = expand(parse(doc), test_impact());
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].job_id, b[i].job_id);
  doc["axes"][0]["values"].push_back(3.71);
  const auto c = expand(parse(doc), test_impact());
  std::set<std::string> old_ids;
  for (const auto& j : a) old_ids.insert(j.job_id);
  std::size_t fresh = 0;
  for (const auto& j : c) fresh += old_ids.count(j.job_id) == 0;
  EXPECT_EQ(fresh, 2u);                               // one new drop and its bed
  EXPECT_EQ(parse(doc).groups[0].axes[0].name, "g");  // name derived from the pointer
}

TEST(SweepSpec, MalformedSpecNamesPointerValueAndExpectedType) {
  const json doc = json::parse(R"({
    "sweep": "bad name!",
    "base": {"g": 9.81, "seed": 1, "name": "x"},
    "axes": [
      {"name": "gravity_m_s2", "pointer": "/g", "values": [9.81, "1.62"]},
      {"pointer": "/gravty", "values": [1]},
      {"name": "seed", "pointer": "/seed", "values": [1, 2.5]},
      {"pointer": "/g", "range": {"start": 1, "stop": 2, "step": -1}}
    ],
    "max_attempts": "three",
    "colour": "blue"
  })");
  const auto ps = problems_of(doc);
  EXPECT_TRUE(has_problem(ps, "/sweep", "\"bad name!\" (string)", "sweep name")) << ps.size();
  EXPECT_TRUE(has_problem(ps, "/axes/0/values/1", "\"1.62\" (string)", "a number"));
  EXPECT_TRUE(has_problem(ps, "/axes/1/pointer", "\"/gravty\"", "present in the base scenario"));
  // Numbers are numbers: 2.5 may replace an integer base value; the
  // scenario schema of an impact sweep still refuses a non-integer where it needs one.
  EXPECT_FALSE(has_problem(ps, "/axes/2/values/1", "2.5 (number)", "an integer"));
  EXPECT_TRUE(has_problem(ps, "/axes/3/range/step", "-1 (integer)", "a positive number"));
  EXPECT_TRUE(has_problem(ps, "/max_attempts", "\"three\" (string)", "an integer"));
  EXPECT_TRUE(has_problem(ps, "/colour", "unknown key", "one of"));
  // The message carries all of it, with the file name.
  try {
    parse(doc);
  } catch (const SpecError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("spec.json"), std::string::npos);
    EXPECT_NE(m.find("/axes/0/values/1: found \"1.62\" (string), expected a number"), std::string::npos) << m;
    EXPECT_NE(m.find("nothing was written"), std::string::npos);
  }
}

TEST(SweepSpec, ZipLengthsAndDuplicatesAreRefused) {
  const json doc = {
      {"sweep", "s"},
      {"base", kBase},
      {"axes",
       {{{"zip", {{{"pointer", "/fill_m"}, {"values", {0.1, 0.2}}}, {{"pointer", "/dt_s"}, {"values", {1e-5}}}}}},
        {{"pointer", "/g"}, {"values", {1.0, 1}}}}}};
  const auto ps = problems_of(doc);
  EXPECT_TRUE(has_problem(ps, "/axes/0/zip/1", "1 values", "2 values"));
  EXPECT_TRUE(has_problem(ps, "/axes/1/values/1", "1", "differ"));  // 1.0 and 1 are the same value
}

TEST(SweepSpec, JsonSyntaxErrorNamesLineAndColumn) {
  gravsweep::test::TempDir dir;
  gravsweep::test::write_text(dir.path / "s.json", "{\n  \"sweep\": \"a\",\n  \"base\": {,}\n}\n");
  try {
    load_spec(dir.path / "s.json");
    FAIL() << "syntax error accepted";
  } catch (const SpecError& e) {
    EXPECT_NE(std::string(e.what()).find("s.json:3:"), std::string::npos) << e.what();
  }
}

TEST(SweepSpec, BaseFromFileRelativeToSpec) {
  gravsweep::test::TempDir dir;
  gravsweep::test::write_text(dir.path / "base.json", kBase.dump());
  gravsweep::test::write_text(dir.path / "s.json", R"({"sweep": "f", "base": "base.json",
     "axes": [{"pointer": "/nested/k", "values": [1.5, 2.5]}]})");
  const auto spec = load_spec(dir.path / "s.json");
  EXPECT_EQ(spec.groups[0].axes[0].name, "nested_k");
  EXPECT_EQ(spec.points(), 2u);
}

TEST(SweepSpec, StoredTextIsTheSpecAsWrittenWithItsBaseInlined) {
  // The sweeps row stores the spec as written (no defaults filled, a range as a range), its base
  // inlined and canonical, as canonical text with its SHA-256: the same text earlier builds stored,
  // worked out here from the file for every committed spec.
  namespace fs = std::filesystem;
  std::size_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(GRAVSWEEP_SOURCE_DIR) / "examples")) {
    if (e.path().extension() != ".json") continue;
    std::ifstream in(e.path());
    json written = json::parse(in, nullptr, false);
    if (!written.is_object() || !written.contains("sweep")) continue;
    if (written["base"].is_string()) {
      std::ifstream base_in(e.path().parent_path() / written["base"].get<std::string>());
      written["base"] = json::parse(base_in);
    }
    written["base"] = gravsweep::queue::canonicalize(written["base"]);
    EXPECT_EQ(load_spec(e.path()).spec_json, gravsweep::queue::canonical_json(written)) << e.path();
    ++n;
  }
  EXPECT_GE(n, 20u) << "the sweep specs under examples/";
  // The hash the sweeps row of examples/sweep_tiny.json has held since it was written.
  EXPECT_EQ(
      gravsweep::queue::sha256_hex(load_spec(fs::path(GRAVSWEEP_SOURCE_DIR) / "examples/sweep_tiny.json").spec_json),
      "7f863e1f6511f56ab353a46f7e997707e333588b4bdca5b9e0450080886665c1");
  // Defaults the schema fills are the record's, not the stored text's.
  const SweepSpec bare = parse({{"sweep", "s"}, {"base", kBase}, {"axes", {{{"pointer", "/g"}, {"values", {1}}}}}});
  EXPECT_EQ(bare.max_attempts, 3);
  EXPECT_FALSE(json::parse(bare.spec_json).contains("max_attempts"));
}

TEST(SweepSpec, ErrorIsTheOneSpecErrorAConfigErrorWithTheSweepMessage) {
  // One SpecError for scenario and sweep specs (spec/json_schema.h); a sweep spec's message
  // stays as it was: the file, the count, then one line per problem.
  const json doc = {{"sweep", "s"},
                    {"base", kBase},
                    {"axes", {{{"pointer", "/g"}, {"values", {1.62, 9.81}}}}},
                    {"colour/x", 1},
                    {"max_attempts", 0}};
  try {
    parse(doc);
    FAIL() << "an unknown key and max_attempts 0 accepted";
  } catch (const gravsweep::ConfigError& e) {
    const auto* se = dynamic_cast<const gravsweep::spec::SpecError*>(&e);
    ASSERT_NE(se, nullptr) << "not a SpecError: " << e.what();
    EXPECT_EQ(se->source(), "spec.json");
    ASSERT_EQ(se->problems().size(), 2u) << e.what();
    const std::string first = "\n  /colour~1x: found unknown key \"colour/x\", expected one of: ";
    EXPECT_EQ(std::string(e.what()).rfind("spec.json: invalid sweep spec (2 problems); nothing was written" + first, 0),
              0u)
        << e.what();
    EXPECT_EQ(se->pointer(), "/colour~1x");
    EXPECT_NE(std::string(e.what()).find("\n  /max_attempts: found 0 (integer), expected "), std::string::npos)
        << e.what();
  }
}

// The typed scenario (scheduler/pipeline/scenario.h): every committed scenario and every point of
// the committed sweep specs reads into the record and back to the same JSON (and the same
// canonical text, which job ids and the site seed are computed from); the engine's inputs built
// from the record draw the same projectile sites as the committed drops.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "scheduler/pipeline/impact_runners.h"
#include "scheduler/pipeline/scenario.h"
#include "scheduler/pipeline/scenario_spec.h"
#include "scheduler/queue/canonical.h"
#include "scheduler/sweep/spec.h"
#include "scheduler/sweep/sweep_kind.h"
#include "scenario_helpers.h"

namespace gravsweep {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

const fs::path kRoot = GRAVSWEEP_SOURCE_DIR;

/// The site seed as the scenario's JSON defines it (scenario.schema.json, /projectile/site_draw),
/// written out here from the validated JSON, independently of the record.
std::uint64_t site_seed_from_json(const json& s) {
  const json& pj = s.at("projectile");
  if (pj.at("site_draw") == "seed") return pj.at("seed").get<std::uint64_t>();
  const json point{{"gravity_m_s2", s.at("gravity_m_s2")},
                   {"projectile", pj},
                   {"grains", s.at("grains")},
                   {"container", s.at("container")}};
  return std::stoull(queue::sha256_hex(queue::canonical_json(point)).substr(0, 16), nullptr, 16);
}

/// The record of `validated` gives it back, as JSON and as canonical text, and its site seed.
void expect_round_trip(const json& validated, const std::string& what) {
  const pipeline::Scenario r = pipeline::scenario_of(validated);
  const json back = pipeline::to_json(r);
  EXPECT_EQ(back, validated) << what;
  EXPECT_EQ(queue::canonical_json(back), queue::canonical_json(validated)) << what;
  EXPECT_EQ(r.site_seed(), site_seed_from_json(validated)) << what;
}

TEST(ScenarioRecord, EveryCommittedDropsScenarioReadsIntoTheRecordAndBack) {
  std::size_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(kRoot / "data")) {
    if (e.path().extension() != ".json" || e.path().parent_path().filename() != "scenarios") continue;
    std::ifstream in(e.path());
    const json validated = pipeline::validate_scenario(json::parse(in), e.path().string());
    expect_round_trip(validated, e.path().string());
    ++n;
  }
  EXPECT_GE(n, 240u) << "the committed drops' scenarios (data/*/*/scenarios/)";
}

TEST(ScenarioRecord, EveryPointOfTheCommittedSweepSpecsReadsIntoTheRecordAndBack) {
  const sweep::SweepKind kind = pipeline::impact_sweep_kind();
  std::size_t points = 0;
  for (const auto& e : fs::recursive_directory_iterator(kRoot / "examples")) {
    if (e.path().extension() != ".json") continue;
    std::ifstream in(e.path());
    const json doc = json::parse(in, nullptr, false);
    if (!doc.is_object() || !doc.contains("sweep") || doc.value("job", "impact") != "impact") continue;
    for (const auto& j : sweep::expand(sweep::load_spec(e.path()), kind)) {
      const auto stored = pipeline::StoredScenario::parse(json::parse(j.scenario_json));
      ASSERT_TRUE(stored.validated_by.has_value()) << e.path();
      expect_round_trip(stored.validated, e.path().string() + " job " + j.job_id);
      EXPECT_EQ(stored.to_json(), json::parse(j.scenario_json)) << "the stored form is kept";
      ++points;
    }
  }
  EXPECT_GE(points, 100u) << "the sweep specs under examples/";
}

TEST(ScenarioRecord, EveryOptionalFieldHasItsPlace) {
  json s = test::tiny_scenario();
  s["$schema"] = "../schemas/scenario.schema.json";
  s["defaults_version"] = 2;
  s["bed"]["lid"] = true;
  s["bed"]["placement_spacing_diameters"] = 1.1;
  s["bed"]["settle"]["plateau_window_s"] = 0.1;
  s["bed"]["quench"] = {{"interval_s", 5e-4}, {"time_s", 2}};
  s["bed"]["surface_relax_s"] = 0.1;
  s["bed"]["time_step"] = {{"steps_per_contact", 20}, {"dt_max_s", 5e-5}, {"pour", true}};
  s["bed"]["materials"] = {{"grain", {{"mu_rolling", 0.2}}}};
  s["contact"]["pairs"]["grain-projectile"] = {{"mu_static", 0.3}};
  s["stop"]["speed_m_s"] = 2e-3;
  s["time_step"] = {{"steps_per_contact", 20}, {"dt_max_s", 5e-5}, {"speed_bound", "normal_approach"}};
  s["at_rest"]["surface_radius_D"] = 1.5;
  s["rolling_threshold"] = {{"min_roll_vel_m_s", 1e-5}};
  const json validated = pipeline::validate_scenario(s);
  expect_round_trip(validated, "every optional field");
  const pipeline::Scenario r = pipeline::scenario_of(validated);
  EXPECT_EQ(r.bed.lid, true);
  EXPECT_EQ(r.bed.time_step->pour, true);
  EXPECT_DOUBLE_EQ(r.bed_materials().grain.mu_rolling, 0.2);
  EXPECT_DOUBLE_EQ(*r.contact.pairs.at("grain-projectile").mu_static, 0.3);
  EXPECT_EQ(r.time_step->speed_bound, "normal_approach");
  EXPECT_DOUBLE_EQ(r.drop_stop().speed_m_s, 2e-3);
  EXPECT_DOUBLE_EQ(r.drop_config().options.min_roll_vel_m_s, 1e-5);
}

TEST(ScenarioRecord, AKeyTheRecordDoesNotHaveIsRefusedNamingItsPointer) {
  json s = pipeline::validate_scenario(test::tiny_scenario());
  s["bed"]["settle"]["typo_s"] = 1;
  try {
    (void)pipeline::scenario_of(s);
    FAIL() << "a key the record does not have was read silently";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/bed/settle/typo_s"), std::string::npos) << e.what();
  }
  json wrong = pipeline::validate_scenario(test::tiny_scenario());
  wrong["projectile"]["seed"] = "one";
  try {
    (void)pipeline::scenario_of(wrong);
    FAIL() << "a seed of the wrong type was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/projectile/seed"), std::string::npos) << e.what();
  }
}

TEST(ScenarioRecord, TheStoredFormSplitsIntoTheScenarioAndItsMarks) {
  const json validated = pipeline::validate_scenario(test::tiny_scenario());
  const json written = {{"projectile", {{"impact_speed_m_s", 1.0}}}};
  const json stored = pipeline::StoredScenario::of_this_build(validated, written).to_json();
  const auto parts = pipeline::StoredScenario::parse(stored);
  EXPECT_EQ(parts.validated, validated);
  EXPECT_EQ(parts.validated_by, pipeline::validated_by());
  EXPECT_EQ(parts.as_written, written);
  const auto unmarked = pipeline::StoredScenario::parse(validated);
  EXPECT_FALSE(unmarked.validated_by.has_value());
  EXPECT_FALSE(unmarked.as_written.has_value());
  json bad = stored;
  bad[pipeline::StoredScenario::kValidatedByKey] = 7;
  EXPECT_THROW((void)pipeline::StoredScenario::parse(bad), pipeline::SpecError);
}

}  // namespace
}  // namespace gravsweep

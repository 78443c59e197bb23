// Versioned defaults (scheduler/pipeline/scenario_defaults.h): a new scenario at low gravity takes
// the checked adaptive step, a job stored before versions existed runs as it was submitted, and the
// committed sweeps keep their job ids.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "scheduler/pipeline/impact_runners.h"
#include "scheduler/pipeline/scenario_defaults.h"
#include "scheduler/pipeline/scenario_spec.h"
#include "scheduler/queue/canonical.h"
#include "scheduler/sweep/impact_kinds.h"
#include "scheduler/sweep/spec.h"
#include "scheduler_test_helpers.h"

namespace gravsweep {
namespace {

/// The impact kind as `submit` plans it.
const gravsweep::sweep::SweepKind& impact() {
  static const auto kind = gravsweep::pipeline::impact_sweep_kind();
  return kind;
}

using nlohmann::json;
namespace fs = std::filesystem;

json point(double g) { return json{{"gravity_m_s2", g}, {"projectile", {{"impact_speed_m_s", 0.5}}}}; }

/// The validated scenario of `p` as a new spec means it (submit and run record the current version).
json new_scenario(const json& p) { return pipeline::validate_scenario(pipeline::with_current_defaults(p)); }

TEST(DefaultsVersion, ANewScenarioAtLowGravityTakesTheCheckedAdaptiveStep) {
  for (double g : {0.001, 0.01, 0.1}) {
    const json s = new_scenario(point(g));
    ASSERT_TRUE(s.contains("time_step")) << "g " << g;
    EXPECT_EQ(s["/time_step/speed_bound"_json_pointer], "normal_approach");
    EXPECT_EQ(s["/time_step/steps_per_contact"_json_pointer].get<double>(), pipeline::kDefaultStepsPerContact);
    EXPECT_EQ(s["/time_step/dt_max_s"_json_pointer].get<double>(), pipeline::kDefaultDtMax_s);
    EXPECT_EQ(s.at("defaults_version"), pipeline::kCurrentDefaultsVersion);
    EXPECT_EQ(pipeline::validate_scenario(s), s) << "validating a validated scenario changes nothing";
  }
}

TEST(DefaultsVersion, TheFixedStepStaysWhereTheCheckDoesNotReach) {
  for (double g : {9.81, 1.62, 0.0005}) EXPECT_FALSE(new_scenario(point(g)).contains("time_step")) << "g " << g;
  json verlet = point(0.01);
  verlet["integrator"] = "velocity_verlet";
  EXPECT_FALSE(new_scenario(verlet).contains("time_step")) << "checked with semi-implicit Euler only";
}

TEST(DefaultsVersion, AScenarioThatNamesVersionOneOrNoneKeepsTheFixedStep) {
  json v1 = point(0.01);
  v1["defaults_version"] = 1;
  EXPECT_FALSE(new_scenario(v1).contains("time_step"));
  // A job stored before versions existed: its point as written names none, and means version 1.
  EXPECT_FALSE(pipeline::validate_scenario(point(0.01)).contains("time_step"));
  json stored =
      pipeline::StoredScenario::of_this_build(pipeline::validate_scenario(point(0.01)), point(0.01)).to_json();
  stored[pipeline::StoredScenario::kValidatedByKey] = "another build";
  EXPECT_FALSE(pipeline::job_scenario(stored).contains("time_step")) << "revalidated by a newer build";
}

TEST(DefaultsVersion, AStepTheSpecGivesIsKept) {
  json p = point(0.01);
  p["time_step"] = {{"steps_per_contact", 30}, {"dt_max_s", 2e-5}};
  const json s = new_scenario(p);
  EXPECT_EQ(s["/time_step/steps_per_contact"_json_pointer].get<double>(), 30);
  EXPECT_FALSE(s.at("time_step").contains("speed_bound"));
}

/// The drop job ids of the sweep `spec` as `submit` plans them.
std::set<std::string> drop_ids(const sweep::SweepSpec& spec) {
  std::set<std::string> ids;
  for (const auto& j : sweep::expand(spec, impact()))
    if (j.kind == sweep::drop_kind()) ids.insert(j.job_id);
  return ids;
}

TEST(DefaultsVersion, TheCommittedSweepsKeepTheirJobIds) {
  // Every drop of these specs is committed under its job id (data/*/<folder>/scenarios/<id>.json).
  const fs::path root(GRAVSWEEP_SOURCE_DIR);
  std::set<std::string> committed;
  for (const char* dataset : {"data/gravity_sweep", "data/projectile_sweep"})
    for (const auto& folder : fs::directory_iterator(root / dataset))
      if (fs::is_directory(folder.path() / "scenarios"))
        for (const auto& f : fs::directory_iterator(folder.path() / "scenarios"))
          committed.insert(f.path().stem().string());
  std::size_t checked = 0;
  for (const char* spec : {"examples/gravity_sweep/g9.81.json", "examples/gravity_sweep/g1.62.json",
                           "examples/gravity_sweep/g0.1_axis.json", "examples/gravity_sweep/g0.01_axis.json",
                           "examples/gravity_sweep/g0.001_axis.json", "examples/gravity_sweep/poured/g0.1_poured.json",
                           "examples/projectile_sweep/g9.81_d10cm.json", "examples/projectile_sweep/g0.1_d5cm.json"}) {
    for (const auto& id : drop_ids(sweep::load_spec(root / spec))) {
      EXPECT_TRUE(committed.count(id)) << spec << ": drop " << id << " is not a committed job id";
      ++checked;
    }
  }
  EXPECT_EQ(checked, 72u) << "the drops of these specs";
}

TEST(DefaultsVersion, ALowGravitySweepWithoutAStepGetsNewIdsAndPinningVersionOneGivesTheOldOnes) {
  json doc = {
      {"sweep", "slow"},
      {"base", point(0.01)},
      {"axes", {{{"name", "impact_speed_m_s"}, {"pointer", "/projectile/impact_speed_m_s"}, {"values", {0.05, 0.1}}}}}};
  const auto current = sweep::load_spec_text(doc.dump(), "slow.json", ".");
  doc["base"]["defaults_version"] = 1;
  const auto pinned = sweep::load_spec_text(doc.dump(), "slow.json", ".");
  doc["base"].erase("defaults_version");
  const auto ids_now = drop_ids(current), ids_pinned = drop_ids(pinned);
  ASSERT_EQ(ids_now.size(), 2u);
  for (const auto& id : ids_now) EXPECT_FALSE(ids_pinned.count(id)) << "a job that runs differently, another id";
  // The ids of version 1 are those of the point as written before versions existed.
  for (const auto& j : sweep::expand(pinned, impact()))
    if (j.kind == sweep::drop_kind()) {
      const json stored = json::parse(j.scenario_json);
      json as_written = stored.at(pipeline::StoredScenario::kAsWrittenKey);
      as_written.erase("defaults_version");
      EXPECT_EQ(j.job_id, queue::job_id(queue::kind_name(j.kind), as_written));
      EXPECT_FALSE(stored.contains("time_step"));
    }
  for (const auto& j : sweep::expand(current, impact())) {
    if (j.kind == sweep::drop_kind()) {
      EXPECT_TRUE(json::parse(j.scenario_json).contains("time_step"));
    }
  }
}

TEST(DefaultsVersion, AJobNamesItsVersionOnlyWhereItChangesWhatItRuns) {
  // A worker of a build before versions validates the point as written: it must not meet the
  // field where the version changes nothing.
  const auto spec = sweep::load_spec(fs::path(GRAVSWEEP_SOURCE_DIR) / "examples/gravity_sweep/g0.01_axis.json");
  for (const auto& j : sweep::expand(spec, impact())) {
    const json stored = json::parse(j.scenario_json);
    EXPECT_FALSE(stored.at(pipeline::StoredScenario::kAsWrittenKey).contains("defaults_version")) << j.job_id;
    EXPECT_FALSE(stored.contains("defaults_version")) << j.job_id;
  }
}

TEST(DefaultsVersion, SubmitSaysWhichJobsTakeTheNewDefaultAndHowToKeepTheOld) {
  test::TempDir d;
  std::ifstream in(fs::path(GRAVSWEEP_SOURCE_DIR) / "examples" / "sweep_tiny.json");
  json doc = json::parse(in);
  doc["axes"][0]["values"] = {0.01, 9.81};  // one level in the checked range, one above it
  std::ofstream(d.path / "lowg.json") << doc.dump();
  const auto r = test::run_cli({"submit", "lowg.json", "--dry-run"}, d.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("6 jobs take the adaptive step of defaults version 2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"defaults_version\": 1 in the base"), std::string::npos) << r.out;
  doc["base"]["defaults_version"] = 1;
  std::ofstream(d.path / "pinned.json") << doc.dump();
  const auto pinned = test::run_cli({"submit", "pinned.json", "--dry-run"}, d.path);
  EXPECT_EQ(pinned.out.find("adaptive step"), std::string::npos) << pinned.out;
}

}  // namespace
}  // namespace gravsweep

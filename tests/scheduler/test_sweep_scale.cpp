// A large sweep: its points are validated without building an engine System per
// point (the engine's checks run once per distinct set of the fields they read), a long expansion
// shows its progress with an ETA on stderr, and the cap is about cost: a sweep whose expansion would
// not fit the machine is refused with the memory and time it would take and what is allowed.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "scheduler/pipeline/scenario_spec.h"
#include "scheduler/pipeline/impact_runners.h"
#include "scheduler/sweep/spec.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::sweep;
using gravsweep::test::run_cli;
using gravsweep::test::TempDir;
using nlohmann::json;

namespace {

/// The impact kind as `submit` plans it.
const gravsweep::sweep::SweepKind& impact() {
  static const auto kind = gravsweep::pipeline::impact_sweep_kind();
  return kind;
}

/// examples/sweep_tiny.json with `speeds` impact speeds times `repeats` seeds at one gravity.
json tiny_sweep(long speeds, long repeats) {
  std::ifstream in(std::filesystem::path(GRAVSWEEP_SOURCE_DIR) / "examples" / "sweep_tiny.json");
  json s = json::parse(in);
  s["axes"] = json::array({{{"name", "impact_speed_m_s"},
                            {"pointer", "/projectile/impact_speed_m_s"},
                            {"range", {{"start", 0.5}, {"stop", 1.5}, {"num", speeds}}}}});
  s["repeats"] = {{"name", "projectile_seed"}, {"pointer", "/projectile/seed"}, {"count", repeats}, {"start", 1}};
  return s;
}

}  // namespace

TEST(SweepScale, EngineChecksRunOncePerDistinctSetupNotPerPoint) {
  const SweepSpec spec = load_spec_text(tiny_sweep(50, 40).dump(), "big.json", GRAVSWEEP_SOURCE_DIR "/examples");
  const std::size_t before = pipeline::engine_check_runs();
  const auto jobs = expand(spec, impact());
  EXPECT_EQ(jobs.size(), 2001u);  // one bed, 2,000 drops
  // Speeds and seeds are not read by the engine's checks: one run for the whole sweep (two with
  // the base checked alone first), not 2,000.
  EXPECT_LE(pipeline::engine_check_runs() - before, 2u);
  // Every job stores its point validated at submit (defaults filled, marked for the worker), under
  // the id of the point as written; the bed job stores its first drop's.
  for (const auto& job : jobs) {
    const json stored = json::parse(job.scenario_json);
    EXPECT_EQ(stored.at(pipeline::StoredScenario::kValidatedByKey), pipeline::validated_by());
    EXPECT_TRUE(stored.contains("at_rest")) << "a default the base does not write";
    EXPECT_FALSE(stored.at(pipeline::StoredScenario::kAsWrittenKey).contains("at_rest")) << "the point as written";
  }
}

TEST(SweepScale, AnEngineProblemIsStillFoundAtEveryPointThatHasIt) {
  json s = tiny_sweep(3, 2);
  // The time step swept to one the contact law refuses: each point with it is reported, counted.
  s["axes"].push_back({{"name", "dt_s"}, {"pointer", "/dt_s"}, {"values", {1e-5, 1e-2}}});
  const SweepSpec spec = load_spec_text(s.dump(), "big.json", GRAVSWEEP_SOURCE_DIR "/examples");
  try {
    expand(spec, impact());
    FAIL() << "a time step the contact law refuses was accepted";
  } catch (const SpecError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/base/dt_s"), std::string::npos) << what;
    EXPECT_NE(what.find("and 5 more points with this problem"), std::string::npos) << what;
  }
}

TEST(SweepScale, TheCapIsAboutCostAndTheMessageSaysWhatItWouldTake) {
  // A million speeds times a million seeds: the old cap counted points; this one says what the
  // expansion would need, in memory and time, and what this machine allows.
  try {
    load_spec_text(tiny_sweep(1000000, 1000000).dump(), "huge.json", GRAVSWEEP_SOURCE_DIR "/examples");
    FAIL() << "a sweep of 1e12 points was accepted";
  } catch (const SpecError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("huge.json"), std::string::npos) << what;
    EXPECT_NE(what.find("/axes"), std::string::npos) << what;
    EXPECT_NE(what.find("GB of memory"), std::string::npos) << what;
    EXPECT_NE(what.find("min to expand and validate"), std::string::npos) << what;
    EXPECT_NE(what.find("split it into several specs"), std::string::npos) << what;
  }
  // What a sweep is estimated to cost grows with its points and its scenario.
  const auto small =
      expansion_cost(load_spec_text(tiny_sweep(10, 10).dump(), "s.json", GRAVSWEEP_SOURCE_DIR "/examples"));
  const auto large =
      expansion_cost(load_spec_text(tiny_sweep(100, 10).dump(), "s.json", GRAVSWEEP_SOURCE_DIR "/examples"));
  EXPECT_EQ(small.points, 100);
  EXPECT_GT(small.memory_bytes, 100 * 500.0);  // a scenario tree is kilobytes
  EXPECT_GT(small.seconds, 0);
  EXPECT_NEAR(large.memory_bytes, 10 * small.memory_bytes, 1e-9 * large.memory_bytes);
  // 4.9 million points passed the old cap of 5 million; a machine needs the stated memory for them.
  const auto c =
      expansion_cost(load_spec_text(tiny_sweep(4900, 10).dump(), "s.json", GRAVSWEEP_SOURCE_DIR "/examples"));
  EXPECT_GT(c.memory_bytes * 100, 4900 * 1000 * 1000.0);
}

TEST(SweepScale, ALongExpansionShowsItsProgressWithAnEtaOnStderr) {
  TempDir d;
  std::ofstream(d.path / "big.json") << tiny_sweep(250, 100).dump();  // 25,000 points
  const auto r = run_cli({"submit", "big.json", "--dry-run"}, d.path);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("25000 points -> 25001 jobs"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("expanding and validating 25000 points"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("expand"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ETA"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("25000 of 25000 points validated"), std::string::npos) << r.err;
}

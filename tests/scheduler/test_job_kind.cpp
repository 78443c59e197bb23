// A job kind in one registration (scheduler/sweep/sweep_kind.h): this file adds "square" (a side
// per point, its area as the result) and runs a sweep of it through submit, a worker and the
// results table, with nothing else in the tree knowing it.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "scheduler/queue/canonical.h"
#include "scheduler/queue/filter.h"
#include "scheduler/queue/queue.h"
#include "scheduler/queue/worker.h"
#include "scheduler/sweep/spec.h"
#include "scheduler/sweep/sweep_kind.h"
#include "scheduler_test_helpers.h"

namespace gravsweep {
namespace {

using nlohmann::json;

// ---- the kind: all of it -------------------------------------------------------------------

queue::JobKind square_job() {
  static const queue::JobKind kind = queue::register_kind({"square", "squares", ".json", true, false});
  return kind;
}

sweep::SweepKind square_kind() {
  sweep::SweepKind k;
  k.name = "square";
  k.summary = "the area of a square of side side_m";
  k.plan_point = [](const sweep::SweepSpec&, const json& point, queue::PlannedJob job, sweep::Plan& plan) {
    if (!point.value("side_m", json()).is_number() || point["side_m"].get<double>() < 0)
      plan.problem({"/base/side_m", point.value("side_m", json()).dump(), "a length >= 0 (m)"}, job.params);
    job.kind = square_job();
    job.job_id = queue::job_id("square", point);
    job.scenario_json = queue::canonical_json(point);
    plan.add(std::move(job));
  };
  k.runners = {{square_job(), [](const queue::RunContext& ctx) {
                  const double side_m = ctx.claim.scenario.at("side_m");
                  queue::write_file_synced(ctx.output_tmp, json{{"side_m", side_m}}.dump());
                  queue::RunOutput out;
                  out.metrics["area_m2"] = side_m * side_m;
                  return out;
                }}};
  return k;
}

/// Registers the kind once per process (a registry refuses a name twice).
void register_square() {
  static const bool once = (sweep::register_sweep_kind(square_kind()), true);
  (void)once;
}

// ---- the sweep, run ----------------------------------------------------------------------------

json square_sweep(const json& sides) {
  return {{"sweep", "squares"},
          {"job", "square"},
          {"base", {{"side_m", 1.0}}},
          {"axes", {{{"name", "side_m"}, {"pointer", "/side_m"}, {"values", sides}}}}};
}

TEST(JobKind, AKindRegisteredInOneFileRunsThroughSubmitWorkAndResults) {
  register_square();
  test::TempDir dir;
  const auto db_path = dir.path / "c.db";
  {
    db::Database db(db_path.string());
    queue::ensure_schema(db);
    const auto spec = sweep::parse_spec(square_sweep({0.5, 2.0, 3.0}), "squares.json", ".");
    const auto report = queue::submit(db, sweep::record(spec), sweep::expand(spec));
    EXPECT_EQ(report.added, 3u);
  }
  queue::WorkerOptions o;
  o.db_path = db_path;
  o.verbose = false;
  o.poll_s = 0.01;
  const auto rep = queue::run_worker(o, sweep::registered_runners());
  EXPECT_EQ(rep.done, 3);
  db::Database db(db_path.string());
  const auto t = queue::query_results(db, {{}, {"side_m", "area_m2"}, "squares", "side_m", -1});
  ASSERT_EQ(t.rows.size(), 3u);
  for (const auto& row : t.rows) EXPECT_DOUBLE_EQ(row[1].get<double>(), std::pow(row[0].get<double>(), 2));
  EXPECT_EQ(t.rows[2][1].get<double>(), 9.0);
}

TEST(JobKind, AnUnknownKindAndABadPointAreClearErrors) {
  try {
    json cubes = square_sweep({1.0});
    cubes["job"] = "cube";
    (void)sweep::expand(sweep::parse_spec(cubes, "cubes.json", "."));
    FAIL() << "an unknown kind was expanded";
  } catch (const sweep::SpecError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("cubes.json"), std::string::npos) << m;
    EXPECT_NE(m.find("/job"), std::string::npos) << m;
    EXPECT_NE(m.find("noop"), std::string::npos) << "the registered kinds are listed: " << m;
  }
  register_square();
  EXPECT_THROW(sweep::register_sweep_kind(square_kind()), std::exception) << "a name registered twice";
  try {
    (void)sweep::expand(sweep::parse_spec(square_sweep({1.0, -2.0}), "squares.json", "."));
    FAIL() << "a negative side was planned";
  } catch (const sweep::SpecError& e) {
    EXPECT_NE(std::string(e.what()).find("/base/side_m"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("-2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace gravsweep

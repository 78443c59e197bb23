// A job kind in one registration (scheduler/sweep/sweep_kind.h): this file adds "square" (a side
// per point, its area as the result, declared as its output) and runs a sweep of it through
// submit, a worker and the results table, with nothing else in the tree knowing it; and "sloppy",
// whose runner reports a metric it did not declare.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>

#include "scheduler/queue/campaign.h"
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
  static const queue::JobKind kind =
      queue::register_kind({"square", "squares", ".json", true, false, {{"area_m2", "m2", "REAL"}}});
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
                  out.values["area_m2"] = side_m * side_m;
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

/// Submits sweep `doc` to a new campaign at `db_path` (`after_submit` then looks at it), and runs
/// one worker until no job is left.
queue::WorkerReport submit_and_work(const std::filesystem::path& db_path, const json& doc,
                                    const std::function<void(db::Database&)>& after_submit = {}) {
  {
    db::Database db(db_path.string());
    queue::ensure_schema(db);
    const auto spec = sweep::load_spec_text(doc.dump(), doc["sweep"].get<std::string>() + ".json", ".");
    EXPECT_GT(queue::submit(db, spec, sweep::expand(spec)).added, 0u);
    if (after_submit) after_submit(db);
  }
  queue::WorkerOptions o;
  o.db_path = db_path;
  o.verbose = false;
  o.poll_s = 0.01;
  return queue::run_worker(o, sweep::registered_runners());
}

TEST(JobKind, AKindRegisteredInOneFileRunsThroughSubmitWorkAndResults) {
  register_square();
  test::TempDir dir;
  const auto db_path = dir.path / "c.db";
  const auto rep = submit_and_work(db_path, square_sweep({0.5, 2.0, 3.0}), [](db::Database& db) {
    const auto cols = queue::result_columns(db);
    EXPECT_NE(std::find(cols.begin(), cols.end(), "area_m2"), cols.end()) << "declared: a column from submit on";
  });
  EXPECT_EQ(rep.done, 3);
  db::Database db(db_path.string());
  const auto t = queue::query_results(db, {{}, {"side_m", "area_m2"}, "squares", "side_m", -1});
  ASSERT_EQ(t.rows.size(), 3u);
  for (const auto& row : t.rows) EXPECT_DOUBLE_EQ(row[1].get<double>(), std::pow(row[0].get<double>(), 2));
  EXPECT_EQ(t.rows[2][1].get<double>(), 9.0);
}

// ---- a kind whose runner reports more than it declares ---------------------------------------

queue::JobKind sloppy_job() {
  static const queue::JobKind kind =
      queue::register_kind({"sloppy", "sloppies", ".json", true, false, {{"area_m2", "m2", "REAL"}}});
  return kind;
}

void register_sloppy() {
  static const bool once = [] {
    sweep::SweepKind k = square_kind();
    k.name = "sloppy";
    k.plan_point = [](const sweep::SweepSpec&, const json& point, queue::PlannedJob job, sweep::Plan& plan) {
      job.kind = sloppy_job();
      job.job_id = queue::job_id("sloppy", point);
      job.scenario_json = queue::canonical_json(point);
      plan.add(std::move(job));
    };
    k.runners = {{sloppy_job(), [](const queue::RunContext& ctx) {
                    queue::write_file_synced(ctx.output_tmp, "{}");
                    queue::RunOutput out;
                    out.values["area_m2"] = 1.0;
                    out.values["perimeter_m"] = 4.0;  // not declared
                    return out;
                  }}};
    sweep::register_sweep_kind(std::move(k));
    return true;
  }();
  (void)once;
}

TEST(JobKind, AnUndeclaredMetricFailsItsAttemptForGoodAndMakesNoColumn) {
  register_sloppy();
  test::TempDir dir;
  const auto db_path = dir.path / "c.db";
  json doc = square_sweep({1.0});
  doc["sweep"] = doc["job"] = "sloppy";
  const auto rep = submit_and_work(db_path, doc);
  EXPECT_EQ(rep.done, 0);
  EXPECT_EQ(rep.dead, 1) << "a logic error: no retry";
  db::Database db(db_path.string());
  EXPECT_EQ(test::sql_int(db, "SELECT attempts FROM jobs"), 1);
  const std::string error = test::sql_text(db, "SELECT last_error FROM jobs");
  for (const char* part : {"logic error", "'sloppy'", "'perimeter_m'", "area_m2"})
    EXPECT_NE(error.find(part), std::string::npos) << part << " in: " << error;
  EXPECT_EQ(test::sql_int(db, "SELECT count(*) FROM results"), 0);
  const auto cols = queue::result_columns(db);
  EXPECT_EQ(std::find(cols.begin(), cols.end(), "perimeter_m"), cols.end()) << "no column made at completion";
  EXPECT_EQ(test::sql_int(db, "SELECT count(*) FROM jobs WHERE output_path IS NOT NULL"), 0);
  EXPECT_EQ(queue::count_files(dir.path / "c.files" / "sloppies"), 0u) << "its output is not kept";
}

TEST(JobKind, AnOutputThatIsNoColumnIsRefusedAtRegistration) {
  auto refused = [](queue::JobKindInfo info, const std::string& part) {
    try {
      queue::register_kind(std::move(info));
      ADD_FAILURE() << "registered";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  refused({"bad1", "bad1s", ".json", true, false, {{"Area m2", "m2", "REAL"}}}, "'Area m2' is not a plain column");
  refused({"bad2", "bad2s", ".json", true, false, {{"area_m2", "m2", "DOUBLE"}}}, "expected REAL, INTEGER or TEXT");
  refused({"bad3", "bad3s", ".json", true, false, {{"a", "1", "REAL"}, {"a", "1", "REAL"}}}, "declared twice");
  refused({"bad4", "bad4s", ".json", false, false, {{"a", "1", "REAL"}}}, "no results rows");
}

TEST(JobKind, AnUnknownKindAndABadPointAreClearErrors) {
  try {
    json cubes = square_sweep({1.0});
    cubes["job"] = "cube";
    (void)sweep::expand(sweep::load_spec_text(cubes.dump(), "cubes.json", "."));
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
    (void)sweep::expand(sweep::load_spec_text(square_sweep({1.0, -2.0}).dump(), "squares.json", "."));
    FAIL() << "a negative side was planned";
  } catch (const sweep::SpecError& e) {
    EXPECT_NE(std::string(e.what()).find("/base/side_m"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("-2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace gravsweep

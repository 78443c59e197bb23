// The results table's columns on both backends (label postgres: scheduler_postgres_tests): a job
// kind's declared outputs are columns from submit on, before any job finished; a metric a kind
// did not declare is refused at completion, naming the kind and the key, and makes no column; a
// drop's typed record is bound to its columns as it holds its values; a campaign an earlier build
// wrote (its metric columns made at completion, typed by their first value) takes completions of
// this build and reads as before.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "results/processing/metric_fields.h"
#include "scheduler/queue/campaign.h"
#include "scheduler/queue/copy.h"
#include "scheduler/queue/filter.h"
#include "scheduler/queue/queue.h"
#include "scheduler/sweep/impact_kinds.h"
#include "scheduler/sweep/spec.h"
#include "scheduler/sweep/sweep_kind.h"
#include "campaign_store.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::queue;
using gravsweep::test::sql_int;
using gravsweep::test::sql_text;
using nlohmann::json;

namespace {

/// A campaign of the build before outputs were declared (0.1.0+1cdff39b58ea), as `sqlite3 .dump`
/// wrote it: sweep old_drops (a bed and drops at 0.5 and 0.75 m/s of examples/sweep_tiny.json's
/// base, all run by that build's worker), then old_noop (3 noop jobs on an axis gravity_m_s2 of
/// 1, 2, 3 with value 3; one run), then old_drops extended by a drop at 1 m/s (queued). Its metric
/// columns were made at completion: noop_value INTEGER (a first value of 3), resumed_at_s and
/// metrics_error never (no value yet), the DEM's gravity_m_s2 a metric column that the noop
/// sweep's parameter of that name shares.
const char* kEarlierCampaign = GRAVSWEEP_SOURCE_DIR "/tests/scheduler/data/campaign_before_declared_outputs.sql";

std::string read_file(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// Every row of `sql` as text, a line each.
std::string rows_text(db::Database& db, const std::string& sql) {
  db::Statement st(db, sql);
  std::string out;
  while (st.step()) {
    for (int c = 0; c < st.columns(); ++c) out += st.get_text(c) + "|";
    out += "\n";
  }
  return out;
}

/// A value of each declared output's type: what a runner of `kind` could report.
json declared_metrics(JobKind kind, double number) {
  json m = json::object();
  for (const auto& o : kind_info(kind).outputs)
    m[o.key] = o.type == "REAL" ? json(number) : o.type == "INTEGER" ? json(1) : json("text");
  return m;
}

struct ResultColumns : ::testing::TestWithParam<test::Store> {
  test::TempDir dir;
  test::CampaignStore store{GetParam(), dir.path};
  WorkerIdentity me = make_identity("test", 1);
  void SetUp() override {
    if (!store.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << store.skip;
  }
  /// Column name -> its type in results_columns.
  static std::map<std::string, std::string> column_types(db::Database& db) {
    std::map<std::string, std::string> out;
    db::Statement st(db, "SELECT name, sql_type FROM results_columns");
    while (st.step()) out[st.get_text(0)] = st.get_text(1);
    return out;
  }
  Completion done_for(const Claim& c, json metrics) {
    Completion d;
    d.output_rel = c.output_rel;
    d.sha256 = std::string(64, 'a');
    d.bytes = 1;
    d.values = std::move(metrics);
    return d;
  }
};

sweep::CheckedPoint by_gravity(const json& s) { return {s.dump(), {{"g", s["g"]}}, {}}; }

TEST_P(ResultColumns, TheDeclaredColumnsExistRightAfterSubmit) {
  db::Database db(store.location);
  ensure_schema(db);
  const json doc = {{"sweep", "imp"},
                    {"base", {{"g", 9.81}, {"v", 1.0}}},
                    {"axes",
                     {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {9.81, 1.62}}},
                      {{"name", "impact_speed_m_s"}, {"pointer", "/v"}, {"values", {1.0, 2.0}}}}}};
  const auto spec = sweep::load_spec_text(doc.dump(), "imp.json", ".");
  const sweep::SweepKind impact{
      "impact", "test", {}, sweep::shared_input_planner(by_gravity, sweep::drop_kind(), sweep::bed_kind()), {}};
  submit(db, spec, sweep::expand(spec, impact));
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM jobs WHERE state='done'"), 0) << "nothing ran";
  const auto types = column_types(db);
  const auto& outputs = kind_info(sweep::drop_kind()).outputs;
  ASSERT_GT(outputs.size(), 30u) << "the paper's metrics, the DEM's figures, metrics_error";
  for (const auto& o : outputs) {
    // The DEM's gravity_m_s2 meets the swept parameter of that name: the parameter keeps it.
    const std::string name = o.key == "gravity_m_s2" ? "metric_gravity_m_s2" : o.key;
    ASSERT_TRUE(types.count(name)) << name;
    EXPECT_EQ(types.at(name), o.type) << name;
  }
  EXPECT_EQ(types.at("gravity_m_s2"), "REAL");
  EXPECT_EQ(sql_text(db, "SELECT role FROM results_columns WHERE name='gravity_m_s2'"), "param");
  EXPECT_EQ(types.at("rebound"), "INTEGER");
  EXPECT_EQ(types.at("note"), "TEXT");
  EXPECT_EQ(types.at("steps"), "INTEGER");
  EXPECT_EQ(types.size(), outputs.size() + 2) << "two parameters; the bed declares nothing";
  // The table itself has them (a query names them), in the order of their keys after the parameters.
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results WHERE vc_m_s IS NOT NULL OR metrics_error IS NOT NULL"), 0);
  const auto cols = result_columns(db);
  const auto first = std::find(cols.begin(), cols.end(), "apeak_m_s2");
  ASSERT_NE(first, cols.end());
  EXPECT_EQ(first[1], "checkpoint_resumes");
  EXPECT_EQ(cols.back(), "zstop_surface_m");
  // Submitted again: nothing added, nothing moved.
  submit(db, spec, sweep::expand(spec, impact));
  EXPECT_EQ(result_columns(db), cols);
}

TEST_P(ResultColumns, AnUndeclaredMetricOrAWrongTypeIsRefusedAndMakesNoColumn) {
  db::Database db(store.location);
  ensure_schema(db);
  const json doc = {{"sweep", "n"},
                    {"job", "noop"},
                    {"base", {{"g", 1.5}}},
                    {"axes", {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {1.0}}}}}};
  const auto spec = sweep::load_spec_text(doc.dump(), "n.json", ".");
  submit(db, spec, sweep::expand(spec));
  const CampaignPaths paths(store.location, store.files);
  auto c = claim(db, me, paths, 60);
  ASSERT_TRUE(c);
  const auto before = result_columns(db);
  auto refused = [&](const json& metrics, const std::vector<std::string>& parts) {
    try {
      complete(db, *c, done_for(*c, metrics));
      ADD_FAILURE() << "completed with " << metrics.dump();
    } catch (const OutputError& e) {
      for (const auto& p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << p << ": " << e.what();
    }
    EXPECT_EQ(sql_text(db, "SELECT state FROM jobs"), "running") << "the completion rolled back";
    EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results"), 0);
    EXPECT_EQ(result_columns(db), before) << "no column made";
  };
  refused({{"noop_value", 1.0}, {"typo_value", 2.0}}, {"'noop'", "'typo_value'", "noop_value, sleep_s"});
  refused({{"noop_value", "many"}}, {"'noop_value'", "a number"});
  RunOutput listed;
  listed.values = json::array();
  EXPECT_THROW(check_outputs(noop_kind(), listed), OutputError);
  ASSERT_TRUE(complete(db, *c, done_for(*c, {{"noop_value", 7}})));
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results WHERE noop_value=7 AND sleep_s IS NULL"), 1)
      << "a declared output left out is NULL";
}

TEST_P(ResultColumns, ADropsRecordIsBoundToItsColumnsAsItHoldsItsValues) {
  db::Database db(store.location);
  ensure_schema(db);
  const json doc = {{"sweep", "imp"},
                    {"base", {{"g", 9.81}, {"v", 1.0}}},
                    {"axes", {{{"name", "impact_speed_m_s"}, {"pointer", "/v"}, {"values", {1.0, 2.0}}}}}};
  const auto spec = sweep::load_spec_text(doc.dump(), "imp.json", ".");
  const sweep::SweepKind impact{
      "impact", "test", {}, sweep::shared_input_planner(by_gravity, sweep::drop_kind(), sweep::bed_kind()), {}};
  submit(db, spec, sweep::expand(spec, impact));
  const CampaignPaths paths(store.location, store.files);
  auto bed = claim(db, me, paths, 60);
  ASSERT_TRUE(bed && bed->kind == sweep::bed_kind());
  ASSERT_TRUE(complete(db, *bed, done_for(*bed, json::object())));
  // One drop measured, one not (its metrics' numbers and flag null, metrics_error why).
  results::Metrics m;
  m.vc_m_s = 0.975;
  m.rebound = true;
  m.note = "measured";
  for (const bool measured : {true, false}) {
    auto c = claim(db, me, paths, 60);
    ASSERT_TRUE(c && c->kind == sweep::drop_kind());
    auto outputs = std::make_shared<sweep::DropOutputs>();
    outputs->measured = measured;
    if (measured)
      outputs->trace.processed.metrics = m;
    else
      outputs->metrics_error = "no contact";
    outputs->result.steps = 12345;
    outputs->result.first_contact_s = 0.125;
    Completion d = done_for(*c, json::object());
    d.record = outputs;
    check_outputs(c->kind, d);
    // Its text (a trace's `metrics` attribute): every metric, or their numbers and flag null and
    // metrics_error, with the DEM's figures.
    json text = json::object();
    for (const auto& f : results::metric_fields())
      if (measured || !f.text) text[f.key] = measured ? json(m)[f.key] : json(nullptr);
    if (!measured) text["metrics_error"] = "no contact";
    text.update(results::record_json<results::DropRecord>(*outputs, results::dem_figure_fields()));
    EXPECT_EQ(d.outputs_json(), text);
    ASSERT_TRUE(complete(db, *c, d));
    const char* metrics_where =
        measured ? "vc_m_s=0.975 AND rebound=1 AND note='measured' AND metrics_error IS NULL"
                 : "vc_m_s IS NULL AND rebound IS NULL AND note IS NULL AND metrics_error='no contact'";
    EXPECT_EQ(sql_int(db, fmt::format("SELECT count(*) FROM results WHERE job_id='{}' AND {} AND steps=12345 AND "
                                      "first_contact_s=0.125 AND resumed_at_s IS NULL AND stopped=0",
                                      c->job_id, metrics_where)),
              1);
  }
  // A key both as a value and in the record: refused, naming the kind and the key.
  Completion twice;
  twice.values = {{"steps", 1}};
  twice.record = std::make_shared<sweep::DropOutputs>();
  try {
    check_outputs(sweep::drop_kind(), twice);
    ADD_FAILURE() << "a key reported twice was taken";
  } catch (const OutputError& e) {
    for (const char* part : {"'drop'", "'steps'", "twice"})
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST_P(ResultColumns, ACampaignOfTheEarlierLayoutTakesCompletionsAndReadsAsBefore) {
  const std::string sql = read_file(kEarlierCampaign);
  ASSERT_FALSE(sql.empty()) << kEarlierCampaign;
  const auto earlier = dir.path / "earlier.db";
  {
    db::Database file(earlier.string());
    file.exec(sql);
  }
  if (GetParam() == test::Store::postgres) {  // the same campaign on the server, as copied there
    db::Database src(earlier.string()), dst(store.location);
    copy_campaign(src, CampaignPaths(earlier), dst, CampaignPaths(store.location, store.files));
  }
  const std::string location = GetParam() == test::Store::sqlite ? earlier.string() : store.location;
  // The earlier rows, every column but the one widened (its text would read 3.0 for 3).
  const std::string old_rows =
      "SELECT job_id, sweep, kind, bed_job_id, attempt, trace_path, runtime_s, vc_m_s, zstop_m, rebound, note, "
      "steps, gravity_m_s2, sleep_s, impact_speed_m_s FROM results ORDER BY job_id";
  std::string rows_before;
  {
    db::Database db = open_campaign(location, OpenMode::read, store.files);
    EXPECT_EQ(sql_text(db, "SELECT sql_type FROM results_columns WHERE name='noop_value'"), "INTEGER");
    EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results_columns WHERE name='resumed_at_s'"), 0) << "never valued";
    ASSERT_EQ(sql_int(db, "SELECT count(*) FROM results"), 3);
    rows_before = rows_text(db, old_rows);
  }
  db::Database db = open_campaign(location, OpenMode::write, store.files);  // what `work` does
  EXPECT_EQ(rows_text(db, old_rows), rows_before);
  const auto types = column_types(db);
  for (JobKind k : {sweep::drop_kind(), noop_kind()})
    for (const auto& o : kind_info(k).outputs) EXPECT_TRUE(types.count(o.key)) << o.key << " declared on open";
  EXPECT_EQ(types.at("noop_value"), "REAL") << "an INTEGER column of a REAL output widened";
  EXPECT_EQ(sql_text(db, "SELECT role FROM results_columns WHERE name='gravity_m_s2'"), "metric");
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results WHERE vc_m_s > 0 AND steps > 0 AND note IS NOT NULL"), 2)
      << "the earlier drops' rows kept";
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results WHERE noop_value=3 AND gravity_m_s2 IN (1, 2, 3)"), 1);
  const CampaignPaths paths(location, store.files);
  int finished = 0;
  while (auto c = claim(db, me, paths, 60)) {
    json m = c->kind == sweep::drop_kind() ? declared_metrics(c->kind, 0.25) : json{{"noop_value", 2.5}};
    ASSERT_TRUE(complete(db, *c, done_for(*c, m))) << c->kind;
    ++finished;
  }
  EXPECT_EQ(finished, 3) << "the earlier build's queued drop and noop jobs";
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results"), 6);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM results WHERE noop_value=2.5 AND gravity_m_s2 IN (1, 2, 3)"), 2);
  EXPECT_EQ(sql_int(db,
                    "SELECT count(*) FROM results WHERE vc_m_s=0.25 AND resumed_at_s=0.25 AND "
                    "metrics_error='text' AND gravity_m_s2=0.25"),
            1)
      << "the drop's metrics in the columns the earlier build made, and in the new ones";
  const auto t = query_results(db, {{}, {"job_id", "impact_speed_m_s", "vc_m_s"}, "old_drops", "impact_speed_m_s", -1});
  ASSERT_EQ(t.rows.size(), 3u);
  EXPECT_EQ(t.rows[0][1], 0.5);
  EXPECT_GT(t.rows[1][2].get<double>(), t.rows[0][2].get<double>()) << "the earlier drops: faster, faster at contact";
  EXPECT_EQ(t.rows[2][1], 1.0);
  EXPECT_EQ(t.rows[2][2], 0.25);
}

}  // namespace

#ifdef GRAVSWEEP_QUEUE_TESTS_ON_POSTGRES
INSTANTIATE_TEST_SUITE_P(Postgres, ResultColumns, ::testing::Values(test::Store::postgres),
                         [](const auto& info) { return test::store_name(info.param); });
#else
INSTANTIATE_TEST_SUITE_P(Sqlite, ResultColumns, ::testing::Values(test::Store::sqlite),
                         [](const auto& info) { return test::store_name(info.param); });
#endif

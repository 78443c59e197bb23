// `results --where`: parsed, checked against real columns, values bound (never pasted into SQL).
#include <gtest/gtest.h>

#include "scheduler/queue/filter.h"
#include "scheduler/queue/queue.h"
#include "scheduler/sweep/spec.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::queue;

TEST(WhereParser, ConditionsAndConnectors) {
  const auto c = parse_where("gravity_m_s2<1 and speed_m_s >= 2.5, name = 'a b' && ok=true");
  ASSERT_EQ(c.size(), 4u);
  EXPECT_EQ(c[0].column, "gravity_m_s2");
  EXPECT_EQ(c[0].op, "<");
  EXPECT_EQ(c[0].value, 1);
  EXPECT_EQ(c[1].op, ">=");
  EXPECT_EQ(c[1].value, 2.5);
  EXPECT_EQ(c[2].value, "a b");
  EXPECT_EQ(c[3].value, true);
  EXPECT_EQ(parse_where("x==1")[0].op, "=");
  EXPECT_EQ(parse_where("x<>1")[0].op, "!=");
}

TEST(WhereParser, ErrorsNamePositionFoundAndExpected) {
  try {
    parse_where("gravity_m_s2 1");
    FAIL();
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("character 14"), std::string::npos) << m;
    EXPECT_NE(m.find("expected an operator"), std::string::npos) << m;
  }
  EXPECT_THROW(parse_where("g < 1 or g > 2"), std::invalid_argument);
  EXPECT_THROW(parse_where("g<1; DROP TABLE jobs"), std::invalid_argument);
  EXPECT_THROW(parse_where("1<g"), std::invalid_argument);
}

TEST(WhereParser, RowsOutsideADatabaseMatchAsTheResultsTableDoes) {
  const nlohmann::json row = {{"gravity_m_s2", 0.1}, {"sweep", "part2_chrono_lowg"}, {"rebound", false}, {"seed", 2}};
  EXPECT_TRUE(row_matches(row, {"gravity_m_s2<1", "sweep~lowg"}));
  EXPECT_TRUE(row_matches(row, {"seed>=2 and rebound=false"}));
  EXPECT_FALSE(row_matches(row, {"gravity_m_s2<1", "seed!=2"}));
  EXPECT_TRUE(row_matches(row, {}));
  try {
    row_matches(row, {"speed_m_s>1"});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(
        std::string(e.what()).find("found column 'speed_m_s', expected one of: gravity_m_s2, rebound, seed, sweep"),
        std::string::npos)
        << e.what();
  }
}

TEST(ResultsQuery, FiltersAreBoundAndColumnsChecked) {
  test::TempDir dir;
  db::Database db((dir.path / "c.db").string());
  ensure_schema(db);
  nlohmann::json doc = {{"sweep", "s"},
                        {"job", "noop"},
                        {"base", {{"g", 1.5}, {"tag", "a"}}},
                        {"axes",
                         {{{"name", "gravity_m_s2"}, {"pointer", "/g"}, {"values", {0.5, 1.62, 9.81}}},
                          {{"name", "tag"}, {"pointer", "/tag"}, {"values", {"a", "b'); DROP TABLE jobs; --"}}}}}};
  const auto spec = sweep::parse_spec(doc, "t", ".");
  submit(db, sweep::record(spec), sweep::expand(spec, {}));
  const auto me = make_identity("t", 1);
  const CampaignPaths paths(dir.path / "c.db");
  while (auto c = claim(db, me, paths, 60)) {
    Completion d;
    d.output_rel = c->output_rel;
    d.sha256 = "x";
    d.metrics = {{"apeak_m_s2", c->scenario["g"].get<double>() * 10}};
    ASSERT_TRUE(complete(db, *c, d));
  }
  auto t = query_results(db, {{"gravity_m_s2<1"}, {"gravity_m_s2", "apeak_m_s2"}, "", "", -1});
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0][0], 0.5);
  EXPECT_EQ(t.rows[0][1], 5.0);
  t = query_results(
      db, {{"tag = \"b'); DROP TABLE jobs; --\"", "gravity_m_s2 >= 1"}, {"gravity_m_s2"}, "", "gravity_m_s2", -1});
  ASSERT_EQ(t.rows.size(), 2u);
  EXPECT_EQ(t.rows[0][0], 1.62);
  EXPECT_EQ(test::sql_int(db, "SELECT count(*) FROM jobs"), 6) << "the text was a value, not SQL";
  t = query_results(db, {{"tag ~ DROP"}, {}, "", "", -1});
  EXPECT_EQ(t.rows.size(), 3u);
  try {
    query_results(db, {{"gravity<1"}, {}, "", "", -1});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("found column 'gravity', expected one of"), std::string::npos) << e.what();
  }
  EXPECT_THROW(query_results(db, {{}, {"job_id\" FROM jobs --"}, "", "", -1}), std::invalid_argument);
}

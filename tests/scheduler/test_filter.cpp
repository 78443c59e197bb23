// `results --where` on a campaign's results table: columns checked against the real ones, values
// bound (never pasted into SQL). The grammar itself: tests/unit/test_where.cpp.
#include <gtest/gtest.h>

#include "scheduler/queue/filter.h"
#include "scheduler/queue/queue.h"
#include "scheduler/sweep/spec.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;
using namespace gravsweep::queue;

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
  const auto spec = sweep::load_spec_text(doc.dump(), "t", ".");
  submit(db, spec, sweep::expand(spec));
  const auto me = make_identity("t", 1);
  const CampaignPaths paths(dir.path / "c.db");
  while (auto c = claim(db, me, paths, 60)) {
    Completion d;
    d.output_rel = c->output_rel;
    d.sha256 = "x";
    d.values = {{"noop_value", c->scenario["g"].get<double>() * 10}};
    ASSERT_TRUE(complete(db, *c, d));
  }
  auto t = query_results(db, {{"gravity_m_s2<1"}, {"gravity_m_s2", "noop_value"}, "", "", -1});
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

// The `--where` grammar (db/where.h): parsed into conditions, errors naming the position, rows
// outside a database matched as the results table's query matches them.
#include <gtest/gtest.h>

#include "db/where.h"

using namespace gravsweep::db;

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

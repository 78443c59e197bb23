// The database front (db/database.h): SQLite's parameter syntax translated for PostgreSQL, and the
// same statements on both backends (the PostgreSQL half on the tests' throwaway server).
#include <gtest/gtest.h>

#include <map>

#include "campaign_store.h"
#include "db/database.h"
#include "db/postgres.h"
#include "scheduler_test_helpers.h"

using namespace gravsweep;

#ifndef GRAVSWEEP_QUEUE_TESTS_ON_POSTGRES
TEST(DbLayer, ParametersAreTranslatedOutsideLiteralsAndCasts) {
  std::map<std::string, int> names;
  int count = 0;
  EXPECT_EQ(db::translate_parameters("SELECT ?, ?, x FROM t WHERE a=?", names, count),
            "SELECT $1, $2, x FROM t WHERE a=$3");
  EXPECT_EQ(count, 3);
  names.clear();
  EXPECT_EQ(db::translate_parameters("UPDATE t SET a=?2, b=?1 WHERE c=?2", names, count),
            "UPDATE t SET a=$2, b=$1 WHERE c=$2");
  EXPECT_EQ(count, 2);
  names.clear();
  EXPECT_EQ(db::translate_parameters("SET o=:owner, e=:now+:lease, s=:now", names, count), "SET o=$1, e=$2+$3, s=$2");
  EXPECT_EQ(names.at(":now"), 2);
  EXPECT_EQ(count, 3);
  names.clear();
  EXPECT_EQ(db::translate_parameters("SELECT '?:x', \"a?\", 1::float8, ? -- why?\n, ?", names, count),
            "SELECT '?:x', \"a?\", 1::float8, $1 -- why?\n, $2");
  EXPECT_EQ(count, 2);
  EXPECT_TRUE(names.empty());
}

TEST(DbLayer, UrlSelectsPostgres) {
  EXPECT_TRUE(db::is_postgres_url("postgresql://u@h:5432/d"));
  EXPECT_TRUE(db::is_postgres_url("postgres://u@h/d"));
  EXPECT_FALSE(db::is_postgres_url("campaign.db"));
  EXPECT_FALSE(db::is_postgres_url("/data/postgresql/c.db"));
}
#endif

class DbBackends : public ::testing::TestWithParam<test::Store> {};

TEST_P(DbBackends, TypesChangesTransactionsAndErrors) {
  test::TempDir dir;
  const test::CampaignStore store(GetParam(), dir.path);
  if (!store.skip.empty()) GTEST_SKIP() << "PostgreSQL not available: " << store.skip;
  db::Database db(store.location);
  EXPECT_FALSE(db::has_table(db, "t"));
  db.exec("CREATE TABLE t(k TEXT PRIMARY KEY, i BIGINT, r DOUBLE PRECISION, s TEXT)");
  EXPECT_TRUE(db::has_table(db, "t"));
  EXPECT_FALSE(db::has_table(db, "t2"));
  {
    db::Statement ins(db, "INSERT INTO t(k, i, r, s) VALUES(?1, ?2, ?3, ?4)");
    ins.bind(1, "a").bind(2, std::int64_t{1} << 40).bind(3, 0.1).bind(4, "it's");
    ins.run();
    EXPECT_EQ(db.changes(), 1);
    ins.reset();
    ins.bind(1, "b").bind(2, -3).bind(3, 1e-300).bind_null(4);
    ins.run();
  }
  db::Statement st(db, "SELECT k, i, r, s FROM t ORDER BY k");
  ASSERT_TRUE(st.step());
  EXPECT_EQ(st.get_int(1), std::int64_t{1} << 40);
  EXPECT_EQ(st.get_double(2), 0.1) << "doubles round-trip exactly";
  EXPECT_EQ(st.get_text(3), "it's");
  EXPECT_EQ(st.column_type(1), db::ColumnType::integer);
  EXPECT_EQ(st.column_type(2), db::ColumnType::real);
  ASSERT_TRUE(st.step());
  EXPECT_EQ(st.get_double(2), 1e-300);
  EXPECT_TRUE(st.is_null(3));
  EXPECT_FALSE(st.step());
  {
    db::Statement up(db, "UPDATE t SET i=i+1 WHERE k IN ('a','b') RETURNING k");
    int rows = 0;
    while (up.step()) ++rows;
    EXPECT_EQ(rows, 2);
    EXPECT_EQ(db.changes(), 2);
  }
  {  // rolled back unless committed
    db::Transaction tx(db);
    db.exec("DELETE FROM t");
  }
  EXPECT_EQ(test::sql_int(db, "SELECT count(*) FROM t"), 2);
  try {
    db::Statement bad(db, "SELECT nope FROM t");
    bad.step();
    FAIL() << "an unknown column must throw";
  } catch (const db::DbError& e) {
    EXPECT_NE(std::string(e.what()).find("nope"), std::string::npos) << e.what();
  }
}

GRAVSWEEP_INSTANTIATE_ON_THE_QUEUE_BACKEND(DbBackends);

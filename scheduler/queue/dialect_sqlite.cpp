// The job queue's SQL for SQLite (see dialect.h): STRICT tables, rowid keys, the local clock.
#include <fmt/format.h>

#include "scheduler/queue/dialect.h"
#include "scheduler/queue/queue.h"

namespace gravsweep::queue {

namespace {

class SqliteDialect final : public Dialect {
 public:
  [[nodiscard]] SchemaTypes schema_types() const override {
    return {"INTEGER PRIMARY KEY", "INTEGER", "REAL", "STRICT", "STRICT, WITHOUT ROWID"};
  }
  [[nodiscard]] const char* lock_picked_rows() const override { return ""; }
  [[nodiscard]] double now_s(db::Database&) const override { return queue::now_s(); }
  [[nodiscard]] int tables_present(db::Database& db, const std::string& quoted_names) const override {
    db::Statement st(
        db, fmt::format("SELECT count(*) FROM sqlite_master WHERE type='table' AND name IN ({})", quoted_names));
    st.step();
    return static_cast<int>(st.get_int(0));
  }
  [[nodiscard]] bool has_column(db::Database& db, const std::string& table, const std::string& column) const override {
    db::Statement st(db, "SELECT count(*) FROM pragma_table_info(?) WHERE name=?");
    st.bind(1, table).bind(2, column);
    st.step();
    return st.get_int(0) > 0;
  }
  [[nodiscard]] std::string column_type(const std::string& type) const override { return type; }
  [[nodiscard]] std::string add_column_sql(const std::string& table, const std::string& column,
                                           const std::string& sql_type) const override {
    return fmt::format("ALTER TABLE {} ADD COLUMN {} {}", table, column, sql_type);
  }
  void widen_to_real(db::Database& db, const std::string& table, const std::string& column) const override {
    // A STRICT table has no ALTER COLUMN: the table is rebuilt from its own definition with the
    // column's type changed (sqlite.org/lang_altertable.html, "other kinds of table schema
    // changes"); no other table refers to the results table, and it has no other index.
    std::string sql;
    {
      db::Statement st(db, "SELECT sql FROM sqlite_master WHERE type='table' AND name=?");
      st.bind(1, table);
      if (!st.step()) throw db::DbError("no table " + table);
      sql = st.get_text(0);
    }
    // "CREATE TABLE results(" at first, "CREATE TABLE \"results\"(" after a rebuild's rename.
    const std::string from = fmt::format("\"{}\" INTEGER", column);
    const auto at = sql.find(from), head = sql.find('(');
    if (at == std::string::npos || head == std::string::npos || head > at)
      throw db::DbError(fmt::format("cannot find column {} INTEGER in: {}", column, sql));
    sql.replace(at, from.size(), fmt::format("\"{}\" REAL", column));
    sql.replace(0, head, fmt::format("CREATE TABLE {}_widened", table));
    db.exec(sql);
    db.exec(
        fmt::format("INSERT INTO {0}_widened SELECT * FROM {0} ORDER BY rowid; DROP TABLE {0}; "
                    "ALTER TABLE {0}_widened RENAME TO {0}",
                    table));
  }
  [[nodiscard]] std::string contains(const std::string& quoted_column) const override {
    return fmt::format("instr(CAST({} AS TEXT), ?) > 0", quoted_column);
  }
  [[nodiscard]] const char* insertion_order() const override { return "rowid"; }
  void after_copy(db::Database&) const override {}  // rowid keys continue after the largest
};

}  // namespace

const Dialect& sqlite_dialect() {
  static const SqliteDialect d;
  return d;
}

}  // namespace gravsweep::queue

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
    db::Statement st(db, fmt::format("SELECT count(*) FROM sqlite_master WHERE type='table' AND name IN ({})",
                                     quoted_names));
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
  [[nodiscard]] const char* insertion_order() const override { return "rowid"; }
  void after_copy(db::Database&) const override {}  // rowid keys continue after the largest
};

}  // namespace

const Dialect& sqlite_dialect() {
  static const SqliteDialect d;
  return d;
}

}  // namespace gravsweep::queue

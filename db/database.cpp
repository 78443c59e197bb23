#include "db/database.h"

#include "db/postgres.h"
#include "db/sqlite.h"

namespace gravsweep::db {

bool is_postgres_url(std::string_view location) {
  return location.rfind("postgresql://", 0) == 0 || location.rfind("postgres://", 0) == 0;
}

Database::Database(const std::string& location, int busy_timeout_ms, bool read_only)
    : conn_(is_postgres_url(location) ? open_postgres(location, busy_timeout_ms, read_only)
                                      : open_sqlite(location, busy_timeout_ms, read_only)),
      path_(location) {}

Database::~Database() = default;
Database::Database(Database&& o) noexcept = default;
Database& Database::operator=(Database&& o) noexcept = default;

void Database::exec(std::string_view sql) { conn_->exec(sql); }

Statement::Statement(Database& db, std::string_view sql) : cur_(db.connection().prepare(sql)) {}
Statement::~Statement() = default;

Statement& Statement::bind(int idx, std::int64_t v) {
  cur_->bind_int(idx, v);
  return *this;
}
Statement& Statement::bind(int idx, double v) {
  cur_->bind_double(idx, v);
  return *this;
}
Statement& Statement::bind(int idx, std::string_view v) {
  cur_->bind_text(idx, v);
  return *this;
}
Statement& Statement::bind_null(int idx) {
  cur_->bind_null(idx);
  return *this;
}
int Statement::index_of(const char* name) const { return cur_->index_of(name); }
bool Statement::step() { return cur_->step(); }
void Statement::run() {
  while (cur_->step()) {
  }
}
void Statement::reset() { cur_->reset(); }
int Statement::columns() const { return cur_->columns(); }
std::string Statement::column_name(int i) const { return cur_->column_name(i); }
std::int64_t Statement::get_int(int i) const { return cur_->get_int(i); }
double Statement::get_double(int i) const { return cur_->get_double(i); }
std::string Statement::get_text(int i) const { return cur_->get_text(i); }
ColumnType Statement::column_type(int i) const { return cur_->column_type(i); }

Transaction::Transaction(Database& db, Mode mode) : db_(db) { db_.connection().begin(mode); }

Transaction::~Transaction() {
  if (!done_) db_.connection().rollback();
}

void Transaction::commit() {
  db_.exec("COMMIT");
  done_ = true;
}

bool has_table(Database& db, std::string_view name) {
  Statement q(db, db.backend() == Backend::sqlite
                      ? "SELECT 1 FROM sqlite_master WHERE type = 'table' AND name = ?"
                      : "SELECT 1 FROM information_schema.tables WHERE table_schema = current_schema() AND "
                        "table_name = ?");
  q.bind(1, std::string(name));
  return q.step();
}

}  // namespace gravsweep::db

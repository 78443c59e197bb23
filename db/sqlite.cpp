#include "db/sqlite.h"

#include <fmt/format.h>

namespace gravsweep::db {

Database::Database(const std::string& path, int busy_timeout_ms, bool read_only) : path_(path) {
  const int flags = read_only ? SQLITE_OPEN_READONLY : (SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
  const int rc = sqlite3_open_v2(path.c_str(), &db_, flags | SQLITE_OPEN_NOMUTEX, nullptr);
  if (rc != SQLITE_OK) {
    std::string msg = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
    sqlite3_close(db_);
    db_ = nullptr;
    throw DbError(fmt::format("cannot open database '{}': {}", path, msg), rc);
  }
  sqlite3_busy_timeout(db_, busy_timeout_ms);
  sqlite3_extended_result_codes(db_, 0);
  if (!read_only && path != ":memory:") exec("PRAGMA journal_mode=WAL;");
  exec("PRAGMA synchronous=NORMAL; PRAGMA foreign_keys=ON;");
}

Database::~Database() {
  if (db_) sqlite3_close_v2(db_);
}

void Database::exec(std::string_view sql) {
  char* err = nullptr;
  const std::string s(sql);
  const int rc = sqlite3_exec(db_, s.c_str(), nullptr, nullptr, &err);
  if (rc != SQLITE_OK) {
    std::string msg = err ? err : sqlite3_errstr(rc);
    sqlite3_free(err);
    throw DbError(fmt::format("database '{}': {} (in: {})", path_, msg, s.substr(0, 200)), rc);
  }
}

std::int64_t Database::last_insert_rowid() const { return sqlite3_last_insert_rowid(db_); }
int Database::changes() const { return sqlite3_changes(db_); }

Statement::Statement(Database& db, std::string_view sql) : db_(db), sql_(sql) {
  const int rc = sqlite3_prepare_v2(db.handle(), sql_.c_str(), static_cast<int>(sql_.size()), &stmt_, nullptr);
  if (rc != SQLITE_OK)
    throw DbError(fmt::format("database '{}': cannot prepare: {} (in: {})", db.path(),
                              sqlite3_errmsg(db.handle()), sql_.substr(0, 200)),
                  rc);
}

Statement::~Statement() { sqlite3_finalize(stmt_); }

void Statement::check(int rc, const char* what) const {
  if (rc != SQLITE_OK)
    throw DbError(fmt::format("database '{}': {} failed: {} (in: {})", db_.path(), what,
                              sqlite3_errmsg(db_.handle()), sql_.substr(0, 200)),
                  rc);
}

int Statement::index_of(const char* name) const {
  const int i = sqlite3_bind_parameter_index(stmt_, name);
  if (i == 0) throw DbError(fmt::format("no SQL parameter '{}' in: {}", name, sql_.substr(0, 200)), SQLITE_RANGE);
  return i;
}

Statement& Statement::bind(int idx, std::int64_t v) {
  check(sqlite3_bind_int64(stmt_, idx, v), "bind");
  return *this;
}
Statement& Statement::bind(int idx, double v) {
  check(sqlite3_bind_double(stmt_, idx, v), "bind");
  return *this;
}
Statement& Statement::bind(int idx, std::string_view v) {
  check(sqlite3_bind_text(stmt_, idx, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT), "bind");
  return *this;
}
Statement& Statement::bind_null(int idx) {
  check(sqlite3_bind_null(stmt_, idx), "bind");
  return *this;
}

bool Statement::step() {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  const std::string msg = sqlite3_errmsg(db_.handle());
  sqlite3_reset(stmt_);
  throw DbError(fmt::format("database '{}': {} (in: {})", db_.path(), msg, sql_.substr(0, 200)), rc);
}

void Statement::run() {
  while (step()) {
  }
}

void Statement::reset() {
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
}

int Statement::columns() const { return sqlite3_column_count(stmt_); }
std::string Statement::column_name(int i) const { return sqlite3_column_name(stmt_, i); }
bool Statement::is_null(int i) const { return sqlite3_column_type(stmt_, i) == SQLITE_NULL; }
int Statement::column_type(int i) const { return sqlite3_column_type(stmt_, i); }
std::int64_t Statement::get_int(int i) const { return sqlite3_column_int64(stmt_, i); }
double Statement::get_double(int i) const { return sqlite3_column_double(stmt_, i); }
std::string Statement::get_text(int i) const {
  const auto* t = sqlite3_column_text(stmt_, i);
  return t ? std::string(reinterpret_cast<const char*>(t), static_cast<std::size_t>(sqlite3_column_bytes(stmt_, i)))
           : std::string();
}

Transaction::Transaction(Database& db, Mode mode) : db_(db) {
  db_.exec(mode == Mode::immediate ? "BEGIN IMMEDIATE" : mode == Mode::exclusive ? "BEGIN EXCLUSIVE" : "BEGIN");
}

Transaction::~Transaction() {
  if (!done_) sqlite3_exec(db_.handle(), "ROLLBACK", nullptr, nullptr, nullptr);
}

void Transaction::commit() {
  db_.exec("COMMIT");
  done_ = true;
}

}  // namespace gravsweep::db

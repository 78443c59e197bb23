#include "db/sqlite.h"

#include <fmt/format.h>
#include <sqlite3.h>

namespace gravsweep::db {

namespace {

DbError::Kind kind_of(int rc) {
  if (rc == SQLITE_BUSY || rc == SQLITE_LOCKED) return DbError::Kind::busy;
  if (rc == SQLITE_NOTADB || rc == SQLITE_CORRUPT) return DbError::Kind::not_a_database;
  return DbError::Kind::other;
}

class SqliteConnection;

class SqliteCursor final : public detail::Cursor {
 public:
  SqliteCursor(sqlite3* db, const std::string& path, std::string_view sql) : db_(db), path_(path), sql_(sql) {
    const int rc = sqlite3_prepare_v2(db_, sql_.c_str(), static_cast<int>(sql_.size()), &stmt_, nullptr);
    if (rc != SQLITE_OK)
      throw DbError(
          fmt::format("database '{}': cannot prepare: {} (in: {})", path_, sqlite3_errmsg(db_), sql_.substr(0, 200)),
          kind_of(rc));
  }
  ~SqliteCursor() override { sqlite3_finalize(stmt_); }
  SqliteCursor(const SqliteCursor&) = delete;
  SqliteCursor& operator=(const SqliteCursor&) = delete;

  void bind_int(int idx, std::int64_t v) override { check(sqlite3_bind_int64(stmt_, idx, v)); }
  void bind_double(int idx, double v) override { check(sqlite3_bind_double(stmt_, idx, v)); }
  void bind_text(int idx, std::string_view v) override {
    check(sqlite3_bind_text(stmt_, idx, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT));
  }
  void bind_null(int idx) override { check(sqlite3_bind_null(stmt_, idx)); }
  [[nodiscard]] int index_of(const char* name) const override {
    const int i = sqlite3_bind_parameter_index(stmt_, name);
    if (i == 0) throw DbError(fmt::format("no SQL parameter '{}' in: {}", name, sql_.substr(0, 200)));
    return i;
  }
  bool step() override {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    const std::string msg = sqlite3_errmsg(db_);
    sqlite3_reset(stmt_);
    throw DbError(fmt::format("database '{}': {} (in: {})", path_, msg, sql_.substr(0, 200)), kind_of(rc));
  }
  void reset() override {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }
  [[nodiscard]] int columns() const override { return sqlite3_column_count(stmt_); }
  [[nodiscard]] std::string column_name(int i) const override { return sqlite3_column_name(stmt_, i); }
  [[nodiscard]] ColumnType column_type(int i) const override {
    switch (sqlite3_column_type(stmt_, i)) {
      case SQLITE_INTEGER:
        return ColumnType::integer;
      case SQLITE_FLOAT:
        return ColumnType::real;
      case SQLITE_TEXT:
        return ColumnType::text;
      case SQLITE_BLOB:
        return ColumnType::blob;
      default:
        return ColumnType::null;
    }
  }
  [[nodiscard]] std::int64_t get_int(int i) const override { return sqlite3_column_int64(stmt_, i); }
  [[nodiscard]] double get_double(int i) const override { return sqlite3_column_double(stmt_, i); }
  [[nodiscard]] std::string get_text(int i) const override {
    const auto* t = sqlite3_column_text(stmt_, i);
    return t ? std::string(reinterpret_cast<const char*>(t), static_cast<std::size_t>(sqlite3_column_bytes(stmt_, i)))
             : std::string();
  }

 private:
  sqlite3* db_;
  const std::string& path_;
  sqlite3_stmt* stmt_ = nullptr;
  std::string sql_;
  void check(int rc) const {
    if (rc != SQLITE_OK)
      throw DbError(
          fmt::format("database '{}': bind failed: {} (in: {})", path_, sqlite3_errmsg(db_), sql_.substr(0, 200)),
          kind_of(rc));
  }
};

class SqliteConnection final : public detail::Connection {
 public:
  SqliteConnection(const std::string& path, int busy_timeout_ms, bool read_only) : path_(path) {
    const int flags = read_only ? SQLITE_OPEN_READONLY : (SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
    const int rc = sqlite3_open_v2(path.c_str(), &db_, flags | SQLITE_OPEN_NOMUTEX, nullptr);
    if (rc != SQLITE_OK) {
      std::string msg = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
      sqlite3_close(db_);
      db_ = nullptr;
      throw DbError(fmt::format("cannot open database '{}': {}", path, msg), kind_of(rc));
    }
    sqlite3_busy_timeout(db_, busy_timeout_ms);
    sqlite3_extended_result_codes(db_, 0);
    if (!read_only && path != ":memory:") exec("PRAGMA journal_mode=WAL;");
    exec("PRAGMA synchronous=NORMAL; PRAGMA foreign_keys=ON;");
  }
  ~SqliteConnection() override {
    if (db_) sqlite3_close_v2(db_);
  }
  SqliteConnection(const SqliteConnection&) = delete;
  SqliteConnection& operator=(const SqliteConnection&) = delete;

  [[nodiscard]] Backend backend() const override { return Backend::sqlite; }
  void exec(std::string_view sql) override {
    char* err = nullptr;
    const std::string s(sql);
    const int rc = sqlite3_exec(db_, s.c_str(), nullptr, nullptr, &err);
    if (rc != SQLITE_OK) {
      std::string msg = err ? err : sqlite3_errstr(rc);
      sqlite3_free(err);
      throw DbError(fmt::format("database '{}': {} (in: {})", path_, msg, s.substr(0, 200)), kind_of(rc));
    }
  }
  std::unique_ptr<detail::Cursor> prepare(std::string_view sql) override {
    return std::make_unique<SqliteCursor>(db_, path_, sql);
  }
  [[nodiscard]] int changes() const override { return sqlite3_changes(db_); }
  void begin(TxMode mode) override {
    exec(mode == TxMode::immediate ? "BEGIN IMMEDIATE" : mode == TxMode::exclusive ? "BEGIN EXCLUSIVE" : "BEGIN");
  }
  void rollback() noexcept override { sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr); }

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
};

}  // namespace

std::unique_ptr<detail::Connection> open_sqlite(const std::string& path, int busy_timeout_ms, bool read_only) {
  return std::make_unique<SqliteConnection>(path, busy_timeout_ms, read_only);
}

}  // namespace gravsweep::db
